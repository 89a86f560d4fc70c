#!/bin/sh
# Per-event instructions and simulated misses of one workload (see edmd_cachegrind.py):
#   benchmarks/edmd_cachegrind.sh PYTHON DIR WORKLOAD E1 E2 [LL bytes, default 8 MiB]
# prints Ir, D1 misses (reads + writes) and LL misses (reads + writes) per event.
set -e
# a fixed hash seed: Python's start-up then does the same work in both runs
export PYTHONHASHSEED=0
# and no BLAS threads: theirs spin a varying number of instructions
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
py=$1 dir=$2 w=$3 e1=$4 e2=$5 ll=${6:-8388608}
here=$(dirname "$0")
for e in "$e1" "$e2"; do
    valgrind --tool=cachegrind --cache-sim=yes --LL="$ll",16,64 \
        --cachegrind-out-file="$dir/cg.$w.$e.$$" "$py" "$here/edmd_cachegrind.py" run "$dir" "$w" "$e" \
        >"$dir/cg.$w.$e.$$.log" 2>&1
done
summ() { grep '^summary:' "$dir/cg.$w.$1.$$"; }
# events: bar Ir I1mr ILmr Dr D1mr DLmr Dw D1mw DLmw
summ "$e1" | awk '{print $2, $6+$9, $7+$10}' >"$dir/a.$$"
summ "$e2" | awk '{print $2, $6+$9, $7+$10}' >"$dir/b.$$"
paste "$dir/a.$$" "$dir/b.$$" | awk -v n=$(($e2 - $e1)) -v w="$w" \
    '{printf "%-14s Ir/ev %7.0f  D1miss/ev %6.2f  LLmiss/ev %6.2f\n", w, ($4-$1)/n, ($5-$2)/n, ($6-$3)/n}'
rm -f "$dir/a.$$" "$dir/b.$$" "$dir/cg.$w.$e1.$$" "$dir/cg.$w.$e2.$$"
