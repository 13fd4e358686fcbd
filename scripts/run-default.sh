#!/usr/bin/env bash
# The main job on the built-in default: installs what is missing, builds, and
# renders the built-in demo nebula (procedural dust, an O5V star; a = g = 0.6,
# R_V = 5) to out/demo.png, printing what was computed and why. The first run
# also tabulates and caches the scattering table (half a minute on two CPU
# cores). Uses the GPU when one is present. Extra arguments go to
# `nebula render`, e.g. --width 1024 --height 1024.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
echo "building (first time: a few minutes)..."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
if ! cmake --build build -j"$(nproc)" >build/build.log 2>&1; then
  tail -n 40 build/build.log
  echo "build failed; the whole log is build/build.log" >&2
  exit 1
fi
mkdir -p out
build/bin/nebula render --demo --force -o out/demo.png "$@"
