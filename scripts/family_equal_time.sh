#!/usr/bin/env bash
# family_equal_time.sh — equal-time efficiency of an estimator against the path tracer on every
# scene of a generated family (development only, not part of CI).
#
#   restir generate family --kind di --split test --out /tmp/di-test
#   scripts/family_equal_time.sh /tmp/di-test [options]
#
# For each scene listed in DIR/family.txt it renders, interleaved, `--integrator path` and the
# estimator under test with the same `--time-limit`, compares both with a long path-traced
# reference (cached in DIR/ref/, keyed by size and reference time) using `restir compare`, and
# prints per scene each estimator's relMSE, render seconds and efficiency 1/(relMSE·s), the ratio
# estimator/path, and the median ratio over the family. With --reps N it repeats each pair N times
# (alternating which runs first, seeds 1..N) and uses the mean relMSE·s.
#
# The reference's own noise adds to every relMSE: with a reference of R seconds against renders of
# T seconds it adds about T/R of the path tracer's relMSE, and proportionally more to an estimator
# that is better (the printed ratio is then an underestimate). Use a long --ref-time.
#
# Options (defaults in brackets):
#   --bin PATH        restir binary [target/release/restir beside this script's repository]
#   --estimator NAME  restir-di or restir-pt [restir-di for a di family, restir-pt for pt]
#   --time S          seconds per render [2]
#   --ref-time S      seconds of the reference render [60]
#   --width W --height H   image size [160 120]
#   --threads N       worker threads [2]
#   --reps N          repetitions per scene [1]
#   --extra "ARGS"    more options for the estimator under test (e.g. "--light-sampler tiles")
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
bin="$here/target/release/restir"
estimator=""
time_s=2
ref_time=60
width=160
height=120
threads=2
reps=1
extra=""
dir=""
while [[ $# -gt 0 ]]; do
    case "$1" in
        --bin) bin="$(realpath "$2")"; shift 2 ;;
        --estimator) estimator="$2"; shift 2 ;;
        --time) time_s="$2"; shift 2 ;;
        --ref-time) ref_time="$2"; shift 2 ;;
        --width) width="$2"; shift 2 ;;
        --height) height="$2"; shift 2 ;;
        --threads) threads="$2"; shift 2 ;;
        --reps) reps="$2"; shift 2 ;;
        --extra) extra="$2"; shift 2 ;;
        -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
        -*) echo "family_equal_time.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
        *) dir="$1"; shift ;;
    esac
done
if [[ -z "$dir" || ! -f "$dir/family.txt" ]]; then
    echo "family_equal_time.sh: expected a family directory with family.txt (restir generate family ... --out DIR)" >&2
    exit 2
fi
if [[ ! -x "$bin" ]]; then
    echo "family_equal_time.sh: $bin is not an executable (cargo build --release -p restir, or --bin)" >&2
    exit 2
fi
if [[ -z "$estimator" ]]; then
    case "$(grep -m1 -o -- '--kind [a-z]*' "$dir/family.txt" | cut -d' ' -f2)" in
        di) estimator=restir-di ;;
        pt) estimator=restir-pt ;;
        *) echo "family_equal_time.sh: cannot tell the family's kind from family.txt; give --estimator" >&2; exit 2 ;;
    esac
fi

work="$dir/equal-time"
mkdir -p "$dir/ref" "$work"
size=(--width "$width" --height "$height" --threads "$threads" --quiet)

# Render seconds from a --stats JSON file.
seconds() { grep -o '"seconds": [0-9.e+-]*' "$1" | head -1 | awk '{print $2}'; }
# relMSE of a test image against a reference.
relmse() { "$bin" compare "$1" "$2" | grep -o 'relmse=[^ ]*' | cut -d= -f2; }

printf '# %s vs path, %sx%s, %s s per render, reference %s s, %s threads, %s rep(s)%s\n' \
    "$estimator" "$width" "$height" "$time_s" "$ref_time" "$threads" "$reps" \
    "${extra:+, extra: $extra}"
printf '%-52s %12s %7s %10s %12s %7s %10s %7s\n' scene relmse_path s_path eff_path \
    "relmse_$estimator" s_est eff_est ratio
ratios=()
while IFS=$'\t' read -r file _rest; do
    [[ "$file" == \#* || -z "$file" ]] && continue
    name="${file%.ron}"
    scene="$dir/$file"
    ref="$dir/ref/$name-${width}x${height}-${ref_time}s.exr"
    if [[ ! -f "$ref" ]]; then
        "$bin" render "$scene" --integrator path --time-limit "$ref_time" --seed 1000 \
            "${size[@]}" -o "$ref"
    fi
    sum_path=0
    sum_est=0
    s_path_total=0
    s_est_total=0
    for ((rep = 1; rep <= reps; rep++)); do
        order=(path est)
        if ((rep % 2 == 0)); then order=(est path); fi
        for which in "${order[@]}"; do
            if [[ "$which" == path ]]; then
                # shellcheck disable=SC2086
                "$bin" render "$scene" --integrator path --time-limit "$time_s" --seed "$rep" \
                    "${size[@]}" -o "$work/$name-path.exr" --stats "$work/$name-path.json"
                r=$(relmse "$work/$name-path.exr" "$ref")
                s=$(seconds "$work/$name-path.json")
                sum_path=$(awk -v a="$sum_path" -v r="$r" -v s="$s" 'BEGIN{print a + r*s}')
                s_path_total=$(awk -v a="$s_path_total" -v s="$s" 'BEGIN{print a + s}')
                r_path=$r
            else
                # shellcheck disable=SC2086
                "$bin" render "$scene" --integrator "$estimator" --time-limit "$time_s" --seed "$rep" \
                    "${size[@]}" -o "$work/$name-est.exr" --stats "$work/$name-est.json" $extra
                r=$(relmse "$work/$name-est.exr" "$ref")
                s=$(seconds "$work/$name-est.json")
                sum_est=$(awk -v a="$sum_est" -v r="$r" -v s="$s" 'BEGIN{print a + r*s}')
                s_est_total=$(awk -v a="$s_est_total" -v s="$s" 'BEGIN{print a + s}')
                r_est=$r
            fi
        done
    done
    line=$(awk -v rp="$r_path" -v sp="$s_path_total" -v ep="$sum_path" -v re="$r_est" \
        -v se="$s_est_total" -v ee="$sum_est" -v n="$reps" -v name="$name" 'BEGIN{
            effp = n / ep; effe = n / ee;
            printf "%-52s %12.4e %7.2f %10.3f %12.4e %7.2f %10.3f %7.3f", name, rp, sp / n, effp, re, se / n, effe, effe / effp }')
    echo "$line"
    ratios+=("$(echo "$line" | awk '{print $NF}')")
done < "$dir/family.txt"

printf '%s\n' "${ratios[@]}" | sort -g | awk '{a[NR] = $1} END {
    if (NR == 0) { print "no scenes"; exit 1 }
    m = (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2;
    printf "median ratio %.3f over %d scenes (min %.3f, max %.3f)\n", m, NR, a[1], a[NR] }'
