#!/usr/bin/env bash
# Runs on the lent GPU machine (see docs/performance.md): GPU tests, the
# validation suite on CUDA, benchmarks, and the full default table, writing
# logs and files under $OUT. Expects the bundle made by scripts/device-bundle.sh,
# carried as .devpack/ (unpacked here into .devbundle/ when that is absent).
set -uo pipefail
B=${BUNDLE:-.devbundle}
if [ ! -x "$B/bin/nebula" ] && [ -f .devpack/bundle.tar.xz ]; then
  mkdir -p "$B"
  if command -v xz >/dev/null; then tar -C "$B" -xJf .devpack/bundle.tar.xz
  else python3 -c "import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])" .devpack/bundle.tar.xz "$B"; fi
fi
export LD_LIBRARY_PATH=$PWD/$B/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export NEBULA_DATA_DIR=$PWD/data
OUT=${OUT:-/tmp/nebula-out}
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,memory.total --format=csv | tee "$OUT/gpu.txt"
{
  for t in "$B"/bin/*_gpu_tests; do "$t" --gtest_brief=1 || echo "FAILED: $t"; done
  for t in core_tests montecarlo_tests tables_tests illumination_tests raycast_tests axial_tests multires_tests truth_tests pipeline_tests diffuse_tests; do "$B/bin/$t" --gtest_brief=1 || echo "FAILED: $t"; done
} 2>&1 | tee "$OUT/tests.log"
"$B/bin/nebula" validate montecarlo --backend cuda --effort 4 2>&1 | tee "$OUT/validate.log"
"$B/bin/nebula" tabulate --backend cuda -q --photons 1e6 -o "$OUT/table_a0.6_g0.6.h5" 2>&1 | tee "$OUT/tabulate.log"
"$B/bin/nebula" tabulate --backend cuda -q --photons 1e6 --illumination pencil -o "$OUT/table_pencil.h5" 2>&1 | tail -3
"$B/bin/nebula" bench tabulate --backend both --repeats 5 2>&1 | tee "$OUT/bench.log"
"$B/bin/nebula" bench bake --backend both --size 256 --stars 4 2>&1 | tee "$OUT/bench_bake.log"
"$B/bin/nebula" bench render --backend both --size 256 --stars 8 2>&1 | tee "$OUT/bench_render.log"
"$B/bin/nebula" bench axial --backend cuda 2>&1 | tee "$OUT/bench_axial.log"
"$B/bin/nebula" bench axial --backend cuda --emission-only 2>&1 | tee "$OUT/bench_axial_emission_only.log"
"$B/bin/nebula" bench axial --backend cuda --maps full --no-step-aside 2>&1 | tee "$OUT/bench_axial_full_no_step_aside.log"
"$B/bin/nebula" bench reconstruct --backend cuda --map-size 1024 2>&1 | tee "$OUT/bench_reconstruct.log"
"$B/bin/nebula" bench reconstruct --backend cuda --map-size 1024 --maps lopsided --noise 0.02 2>&1 | tee "$OUT/bench_reconstruct_noise.log"
"$B/bin/nebula" render --demo --backend cuda --force -o "$OUT/demo.h5" 2>&1 | tee "$OUT/render_demo.log"
