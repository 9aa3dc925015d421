#!/usr/bin/env bash
# Copy the portable gyrocal files into the Arduino sketch folder (the Arduino IDE compiles only the files
# inside a sketch's own folder). Run from anywhere; pass another sketch folder to copy there instead.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
dest="${1:-$root/examples/arduino/gyrocal_capture}"
cp "$root"/src/gyrocal/c/gyrocal_{cal,frame,session}.{h,c} "$root"/examples/firmware/{board.h,gyrocal_example.h,gyrocal_example.c} "$dest/"
echo "copied the gyrocal C library and the example firmware into $dest"
