#!/usr/bin/env bash
# Bundles the CUDA build's binaries and the libraries they load into
# .devbundle/ for the lent GPU machine (which has CUDA but none of our Debian
# libraries). Build first: cmake -S . -B build -DNEBULA_CUDA=ON && cmake --build build
set -euo pipefail
cd "$(dirname "$0")/.."
bins=(build/bin/nebula build/bin/core_tests build/bin/montecarlo_tests build/bin/tables_tests build/bin/illumination_tests build/bin/raycast_tests)
bins+=(build/bin/*_gpu_tests)
../shared/tools/device-bundle .devbundle "${bins[@]}"
