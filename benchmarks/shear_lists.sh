#!/bin/sh
# Instructions a pair collision of one case of shear_lists.py, between E1 and E2 events:
#   benchmarks/shear_lists.sh PYTHON DIR CASE lists|cells E1 E2
# (DIR holds the states of `shear_lists.py prep DIR`; the counts go there and are removed)
set -e
export PYTHONHASHSEED=0 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
py=$1 dir=$2 case=$3 mode=$4 e1=$5 e2=$6
here=$(dirname "$0")
tag="$case.$mode"
for e in "$e1" "$e2"; do
    valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$dir/scg.$tag.$e.$$" \
        "$py" "$here/shear_lists.py" run "$dir" "$case" "$mode" "$e" >"$dir/scg.$tag.$e.$$.log" 2>&1
done
ir() { grep '^summary:' "$dir/scg.$tag.$1.$$" | awk '{print $2}'; }
field() { grep '^pairs' "$dir/scg.$tag.$2.$$.log" | awk -v k="$1" '{for (i = 1; i < NF; i++) if ($i == k) print $(i + 1)}'; }
a=$(ir "$e1") b=$(ir "$e2") p=$(field pairs "$e1") q=$(field pairs "$e2")
per_pair() { echo "$(field "$1" "$e1") $(field "$1" "$e2") $p $q" | awk '{printf "%.3f", ($2 - $1) / ($4 - $3)}'; }
echo "$case $mode: Ir/pair $(( (b - a) / (q - p) ))  shell exits/pair $(per_pair exits)" \
    " cell crossings/pair $(per_pair crossings)  (pairs $((q - p)) in $((e2 - e1)) events)"
rm -f "$dir/scg.$tag.$e1.$$" "$dir/scg.$tag.$e2.$$" "$dir/scg.$tag.$e1.$$.log" "$dir/scg.$tag.$e2.$$.log"
