#!/bin/bash
# Interleaved rounds of the 20,000-sphere bed: LIGGGHTS 3.8 without and with spatial sorting, then dipper on
# 1 and 2 threads, each on the same settled bed; prints every run and the medians in particle-steps/s.
# Usage: tests/bench/liggghts/compare.sh [ROUNDS] [BUILD_DIR]   (needs: apt-get install liggghts)
set -euo pipefail
rounds=${1:-5}
build=$(realpath "${2:-build}")
here=$(cd "$(dirname "$0")" && pwd)
bench="$build/tests/bench/dipper_bench_bed"
command -v liggghts > /dev/null || { echo "compare.sh: liggghts not found; install Debian's package: apt-get install liggghts" >&2; exit 1; }
[ -x "$bench" ] || { echo "compare.sh: $bench not built; run scripts/build.sh first" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cache="$work/bed20k.bin"
"$bench" --particles 20000 --threads 2 --steps 10 --cache "$cache" > /dev/null
python3 "$here/bed_to_data.py" "$cache" "$work/bed20k.data"
cp "$here/bed.in" "$work/bed.in"
sed 's/^atom_modify map array$/atom_modify map array sort 1000 0.0/' "$here/bed.in" > "$work/bed_sorted.in"
cd "$work"
for k in $(seq 1 "$rounds"); do
    for input in bed.in bed_sorted.in; do
        liggghts -in "$input" > log.txt 2>&1
        seconds=$(grep "Loop time" log.txt | tail -1 | awk '{print $4}')
        echo "liggghts-${input%.in} $(python3 -c "print(round(20000 * 2000 / $seconds))")"
    done
    for threads in 1 2; do
        echo "dipper-${threads}-thread $("$bench" --particles 20000 --threads "$threads" --steps 2000 --cache "$cache" | awk '/particle-steps/ {print $2}')"
    done
done | tee runs.txt
echo "medians (particle-steps/s):"
sort -k1,1 -k2,2n runs.txt | awk '{v[$1] = v[$1] " " $2; c[$1]++} END {for (k in v) {split(substr(v[k], 2), a, " "); printf "  %-22s %.2f M\n", k, a[int((c[k] + 1) / 2)] / 1e6}}'
