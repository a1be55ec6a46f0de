#!/usr/bin/env bash
# Build the tension firmware for the Arduino UNO (both load-cell variants) with Debian's AVR
# toolchain and check that it fits: flash (text + data) <= 32256 B (32 KiB minus the 512 B
# optiboot bootloader) and static RAM (data + bss) <= 2048 B minus a stack margin.
# Then boot the HX711 build in simavr (if installed) and check its banner on the UART.
# Exit status: 0 ok, 1 build failed or does not fit.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SKETCH="$ROOT/firmware/tdcm_tension"
FLASH_MAX=32256
RAM_MAX=2048
STACK_MARGIN=${STACK_MARGIN:-512}
PACKAGES=(arduino-mk arduino-core-avr gcc-avr avr-libc binutils-avr libsimavr-dev libelf-dev)

missing=()
for package in "${PACKAGES[@]}" simavr; do
  dpkg -s "$package" >/dev/null 2>&1 || missing+=("$package")
done
if ((${#missing[@]})); then
  echo "firmware: installing ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

BUILD="$(mktemp -d)"
trap 'rm -rf "$BUILD"' EXIT
status=0
for cell in HX711 ANALOG; do
  objdir="$BUILD/$cell"
  if ! make -s -C "$SKETCH" CELL="$cell" OBJDIR="$objdir" >"$BUILD/make-$cell.log" 2>&1; then
    echo "firmware: FAIL build ($cell); last lines of the log:"
    tail -n 30 "$BUILD/make-$cell.log"
    exit 1
  fi
  read -r text data bss _ < <(avr-size "$objdir/tdcm_tension.elf" | tail -n 1)
  flash=$((text + data))
  ram=$((data + bss))
  ram_max=$((RAM_MAX - STACK_MARGIN))
  verdict=ok
  if ((flash > FLASH_MAX || ram > ram_max)); then verdict=FAIL; status=1; fi
  echo "firmware: $verdict $cell flash ${flash}/${FLASH_MAX} B, RAM ${ram}/${ram_max} B" \
       "(data+bss; ${STACK_MARGIN} B kept for the stack)"
done

if command -v simavr >/dev/null 2>&1; then
  banner="$(timeout 5 simavr -m atmega328p -f 16000000 "$BUILD/HX711/tdcm_tension.elf" 2>&1 \
            | grep -a -o -m 1 '\$1,B,TDCM,[^*]*\*[0-9A-F][0-9A-F]' || true)"
  if [[ -z "$banner" ]]; then
    echo "firmware: FAIL simavr: no banner on the UART within 5 s"
    status=1
  else
    echo "firmware: ok simavr boots the UNO build: $banner"
  fi
fi
exit "$status"
