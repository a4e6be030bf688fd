#!/usr/bin/env bash
# Builds tests/c/oscillator into an FMU: build.sh <output.fmu> [modelDescription.xml]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$(realpath -m "$1")"
xml="${2:-$here/modelDescription.xml}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/binaries/linux64"
gcc -std=c99 -O2 -Wall -Wextra -Werror -fPIC -shared -fvisibility=hidden \
  -o "$work/binaries/linux64/oscillator.so" "$here/oscillator.c" -lm
cp "$xml" "$work/modelDescription.xml"
mkdir -p "$(dirname "$out")"
rm -f "$out"
(cd "$work" && python3 -c 'import sys, zipfile
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as z:
    for p in ("modelDescription.xml", "binaries/linux64/oscillator.so"):
        z.write(p)' "$out")
