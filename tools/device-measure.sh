#!/usr/bin/env bash
# The performance issue's GPU measurements, in phases that each fit one call of a lent GPU
# machine (the device tool: 10 minutes a call, 30 minutes a session; BENCHMARKS.md, "GPU
# figures"). Run from the repository root on that machine:
#
#   tools/device-measure.sh PHASE [PHASE ...]
#
# The phases named share one call's time: each command is stopped at CALL_SECONDS (540) from
# the start, so that what it wrote comes back before the device tool's 600 s limit.
#
#   check       the CUDA step against the CPU's, the block reductions and the size limit
#               (tests/test_gpu_arch.py, test_blocks.py, test_field_limit.py)
#   throughput  the tank block at 1 M and 12 M fluid particles (target: 5e8 particle-steps/s)
#   seed        the 2.5m-drop preset at seed quality to its end, 4 ms (target: under 1 minute)
#   variants    the 12 M tank again with what may pay on a GPU only: cells of side re,
#               a re-sort every 8 steps, the slot-major neighbour list, then the default again
#
# Taichi is not on that machine: `make device-wheels` (here) puts its wheel and dill's in .whl/,
# which the call carries; they are installed into /tmp/site. Every bench run appends its section
# to BENCHMARKS.md (--record); each phase's log and BENCHMARKS.md are copied into $OUT, which the
# device tool brings back. Settings: ARCH (default cuda), TANK_N, PRESET, QUALITY, VARIANT_N,
# STEPS, CALL_SECONDS; DRY_RUN=1 prints the commands instead of running them (tests/test_device_script.py).
set -uo pipefail
cd "$(dirname "$0")/.."

ARCH=${ARCH:-cuda}
TANK_N=${TANK_N:-1000000 12000000}
PRESET=${PRESET:-2.5m-drop}
QUALITY=${QUALITY:-seed}
VARIANT_N=${VARIANT_N:-12000000}
STEPS=${STEPS:-50}
OUT=${OUT:-/tmp/device-measure}
CALL_SECONDS=${CALL_SECONDS:-540}     # every command stops by then: inside a call's 600 s
DRY_RUN=${DRY_RUN:-0}
PHASES="check throughput seed variants"

usage() { echo "usage: tools/device-measure.sh PHASE [PHASE ...]  (phases: $PHASES)" >&2; exit 2; }
[ $# -ge 1 ] || usage
for phase in "$@"; do
  case " $PHASES " in *" $phase "*) ;; *) echo "unknown phase: $phase" >&2; usage ;; esac
done

mkdir -p "$OUT"
export PYTHONUNBUFFERED=1 PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}"

if [ "$DRY_RUN" != 1 ] && ! python3 -c "import taichi" 2>/dev/null; then
  ls .whl/*.whl >/dev/null 2>&1 || { echo "no Taichi here and no .whl/ (make device-wheels)" >&2; exit 2; }
  python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
    --target /tmp/site .whl/*.whl || exit 2
  export PYTHONPATH="/tmp/site:$PYTHONPATH"
fi

started=$(date +%s)        # the phases share one call's time
status=0

# run LOG CMD...: print the command, run it (unless DRY_RUN) into $OUT/LOG.log within the
# call's time, and remember a failure; BENCHMARKS.md is copied after each, so what a command
# recorded comes back even if a later one is killed at the call's limit
run() {
  local log=$1; shift
  echo "+ $*" | tee -a "$OUT/$log.log"
  [ "$DRY_RUN" = 1 ] && return 0
  local left=$(( CALL_SECONDS - ($(date +%s) - started) ))
  if [ "$left" -le 10 ]; then echo "skipped: the call's time is spent" | tee -a "$OUT/$log.log"; status=1; return 1; fi
  timeout "$left" "$@" 2>&1 | tee -a "$OUT/$log.log"
  local rc=${PIPESTATUS[0]}
  cp BENCHMARKS.md "$OUT/" 2>/dev/null
  [ "$rc" = 0 ] || { echo "exit status $rc" | tee -a "$OUT/$log.log"; status=1; }
  return "$rc"
}

# bench LOG ARGS...: crowndemo bench on $ARCH with ARGS, in the environment $BENCH_ENV adds.
# A driver without CUDA's memory pools puts fields in Taichi's preallocated buffer (1 GB by
# default): a run that ran out of it goes once more with a larger one.
bench() {
  local log=$1; shift
  # shellcheck disable=SC2086  # BENCH_ENV is a list of VAR=VALUE words
  run "$log" env ${BENCH_ENV:-} python3 -m crowndemo bench --arch "$ARCH" "$@" && return 0
  if [ "$DRY_RUN" != 1 ] && tail -n 40 "$OUT/$log.log" | grep -q "pre-allocated memory"; then
    # shellcheck disable=SC2086
    run "$log" env ${BENCH_ENV:-} TI_DEVICE_MEMORY_GB=40 python3 -m crowndemo bench \
      --arch "$ARCH" "$@"
  fi
}

finish() {
  cp BENCHMARKS.md "$OUT/" 2>/dev/null
  { nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>/dev/null || true; } \
    > "$OUT/gpu.txt"
}
trap finish EXIT

for phase in "$@"; do
  case $phase in
    check)
      run check python3 -m pytest -q -p no:cacheprovider -n 3 --dist loadfile \
        tests/test_gpu_arch.py tests/test_blocks.py tests/test_field_limit.py ;;
    throughput)
      # shellcheck disable=SC2086  # TANK_N is a list of sizes
      bench throughput --n $TANK_N --steps "$STEPS" --record ;;
    seed)
      bench seed --preset "$PRESET" --quality "$QUALITY" --record ;;
    variants)
      bench variants --n "$VARIANT_N" --steps "$STEPS" --record --set numerics.cells_per_re=1
      bench variants --n "$VARIANT_N" --steps "$STEPS" --record --set numerics.reorder_every=8
      BENCH_ENV=CROWNDEMO_LIST_LAYOUT=slot bench variants --n "$VARIANT_N" --steps "$STEPS" --record
      bench variants --n "$VARIANT_N" --steps "$STEPS" --record ;;
  esac
done
exit "$status"
