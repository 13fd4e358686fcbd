#!/usr/bin/env bash
# Occupancy variants of the tabulator kernel and an Nsight Compute profile,
# on the lent GPU machine (see docs/performance.md for what was learned).
set -uo pipefail
B=${BUNDLE:-.devbundle}
export LD_LIBRARY_PATH=$PWD/$B/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
OUT=${OUT:-/tmp/nebula-out}
mkdir -p "$OUT"
for t in "$B"/bin/*_gpu_tests; do "$t" --gtest_brief=1 || echo "FAILED: $t"; done 2>&1 | tee "$OUT/gpu_tests.log"
for v in nebula nebula_occ4 nebula_occ6 nebula_occ8; do
  [ -x "$B/bin/$v" ] || continue
  echo "== $v"; "$B/bin/$v" bench tabulate --backend cuda --no-convergence --repeats 7
done 2>&1 | tee "$OUT/occupancy.log"
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
"$NCU" --kernel-name regex:sphere_kernel --launch-count 1 --metrics \
smsp__inst_executed.sum,smsp__thread_inst_executed.sum,smsp__thread_inst_executed_per_inst_executed.ratio,\
sm__warps_active.avg.pct_of_peak_sustained_active,smsp__issue_active.avg.pct_of_peak_sustained_active,\
sm__inst_executed_pipe_xu.avg.pct_of_peak_sustained_active,sm__pipe_fma_cycles_active.avg.pct_of_peak_sustained_active,\
gpu__time_duration.sum \
"$B/bin/nebula" tabulate --backend cuda -q --tau-bins 1000 --photons 1e5 -o /tmp/profile.h5 2>&1 | tee "$OUT/ncu.log"
