"""Scene files are read through the bounded YAML loader: hostile files fail fast, one line."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.cli.main import main
from tdcm_ros.errors import TdcmError
from tdcm_ros.scenes import Scene, scene_from_text
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.schema import TOP_KEYS

Stopwatch = Callable[[str], AbstractContextManager[None]]


def _validate(path: Path, capsys: pytest.CaptureFixture[str], stopwatch: Stopwatch,
              label: str) -> str:
    """``tdcm scene validate path``'s one stderr line, after checking exit status 2."""
    with stopwatch(f"tdcm scene validate {label}"):
        status = main(["scene", "validate", str(path)])
    captured = capsys.readouterr()
    err = captured.err.strip()
    with capsys.disabled():
        print(captured.out.strip())  # the stopwatch's line
    assert status == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    return err


def test_hostile_scene_file_exits_2_with_one_line(
        tmp_path: Path, hostile_yaml: tuple[str, str, str],
        capsys: pytest.CaptureFixture[str], stopwatch: Stopwatch) -> None:
    name, text, phrase = hostile_yaml
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    err = _validate(path, capsys, stopwatch, name)
    assert phrase in err and str(path) in err


def test_alias_bomb_under_allowed_keys_is_refused(
        tmp_path: Path, alias_bomb_value: str, capsys: pytest.CaptureFixture[str],
        stopwatch: Stopwatch) -> None:
    path = tmp_path / "laughs.yaml"
    path.write_text(f"name: laughs\nmarkers:\n  labels: {alias_bomb_value}\n"
                    f"schedule:\n  levels: {alias_bomb_value}\n")
    err = _validate(path, capsys, stopwatch, "alias bomb under markers.labels")
    assert f"{path}: line 3: anchors and aliases" in err


def test_duplicate_key_in_a_scene_names_file_line_and_key(tmp_path: Path) -> None:
    path = tmp_path / "dup.yaml"
    path.write_text("name: dup\nschedule:\n  hold_s: 1.0\n  trials: 2\n  hold_s: 3.0\n")
    with pytest.raises(InvalidSceneError, match=r"dup.yaml: line 5: duplicate key 'hold_s'"):
        scene_from_text(path.read_text(), name="dup", source=path)


_SCENE_LINES = st.one_of(
    st.sampled_from(sorted(TOP_KEYS)).map(lambda key: f"{key}: "),
    st.sampled_from(["  levels: ", "  trials: ", "  preset: ", "  labels: ", "  E: ", "  ",
                     "- ", "[", "]", "{", "}", ", ", "&a ", "*a", "1", "-1e+400", "x", "~",
                     "'", "!!float ", "2020-13-01", "tendon_friction: {mu: ", "\n"]))


@settings(max_examples=150)
@given(st.one_of(st.text(max_size=300), st.lists(_SCENE_LINES, max_size=60).map("".join),
                 st.tuples(st.sampled_from(["effects: ", "schedule:\n  levels: "]),
                           st.sampled_from(["[", "{a: ", "- "]), st.integers(0, 3000))
                 .map(lambda t: t[0] + t[1] * t[2])))
def test_scene_loader_returns_a_scene_or_a_typed_error(text: str) -> None:
    try:
        assert isinstance(scene_from_text(text), Scene)
    except TdcmError:
        pass
