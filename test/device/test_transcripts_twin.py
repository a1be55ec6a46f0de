"""The shared protocol transcripts pass on the Python core (the twin's firmware logic)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tdcm_ros.device.transcript import load, mismatches, run_core, to_script

TRANSCRIPTS = sorted((Path(__file__).parent / "transcripts").glob("*.jsonl"))


def test_transcripts_exist() -> None:
    assert len(TRANSCRIPTS) >= 4


@pytest.mark.parametrize("path", TRANSCRIPTS, ids=lambda p: p.stem)
def test_transcript_on_python_core(path: Path) -> None:
    steps = load(path)
    assert mismatches(steps, run_core(to_script(steps))) == []


def test_a_changed_expectation_is_caught() -> None:
    steps = load(TRANSCRIPTS[0])
    index = next(i for i, step in enumerate(steps) if step.get("expect"))
    steps[index] = {"expect": steps[index]["expect"][:-1]}
    assert mismatches(steps, run_core(to_script(steps)))
