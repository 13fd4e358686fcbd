#!/usr/bin/env bash
# Bundles a CUDA build's binaries and the libraries they load into .devbundle/
# for the lent GPU machine (which has CUDA but none of our Debian libraries).
# Build without OpenImageIO first (its libraries are too large to carry):
#   cmake -S . -B build-device -DNEBULA_CUDA=ON -DNEBULA_OPENIMAGEIO=OFF && cmake --build build-device
# then: BUILD=build-device scripts/device-bundle.sh
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build-device}
bins=("$build"/bin/nebula "$build"/bin/core_tests "$build"/bin/montecarlo_tests "$build"/bin/tables_tests
      "$build"/bin/illumination_tests "$build"/bin/raycast_tests "$build"/bin/axial_tests "$build"/bin/multires_tests
      "$build"/bin/truth_tests "$build"/bin/pipeline_tests "$build"/bin/diffuse_tests)
bins+=("$build"/bin/*_gpu_tests)
../shared/tools/device-bundle .devbundle "${bins[@]}" -- scenes
