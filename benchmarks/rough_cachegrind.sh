#!/bin/sh
# Instructions per pair collision of one case, rough or smooth (see rough_cachegrind.py):
#   benchmarks/rough_cachegrind.sh PYTHON DIR CASE rough|smooth E1 E2
set -e
export PYTHONHASHSEED=0 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
py=$1 dir=$2 case=$3 kind=$4 e1=$5 e2=$6
here=$(dirname "$0")
tag=$(echo "$case.$kind" | tr ' ' _)
for e in "$e1" "$e2"; do
    valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$dir/rcg.$tag.$e.$$" \
        "$py" "$here/rough_cachegrind.py" run "$dir" "$case" "$kind" "$e" >"$dir/rcg.$tag.$e.$$.log" 2>&1
done
ir() { grep '^summary:' "$dir/rcg.$tag.$1.$$" | awk '{print $2}'; }
pairs() { grep '^pairs' "$dir/rcg.$tag.$1.$$.log" | awk '{print $2}'; }
a=$(ir "$e1") b=$(ir "$e2") p=$(pairs "$e1") q=$(pairs "$e2")
echo "$case $kind: Ir/pair $(( (b - a) / (q - p) ))  (pairs $((q - p)) in $((e2 - e1)) events)"
rm -f "$dir/rcg.$tag.$e1.$$" "$dir/rcg.$tag.$e2.$$" "$dir/rcg.$tag.$e1.$$.log" "$dir/rcg.$tag.$e2.$$.log"
