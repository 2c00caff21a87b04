#!/usr/bin/env bash
# Interleaved CPU-time comparison of two restir binaries (user CPU seconds, medians).
# Usage: [SIZE=WxH] [THREADS=N] scripts/compare_binaries.sh OLD_BINARY NEW_BINARY [ROUNDS [CASE...]]
# SIZE defaults to 160x120, THREADS to 1. Each CASE is a scene and its flags as one argument
# (default: the cases below; corpus Sponza is added when ../shared/corpus is present).
OLD=$(realpath "$1"); NEW=$(realpath "$2"); R=${3:-3}; T=${THREADS:-1}
W=${SIZE:-160x120}; H=${W#*x}; W=${W%x*}
cd "$(dirname "$0")/.."
SPONZA=../shared/corpus/lajolla/sponza/sponza.xml
cases=("scenes/cornell-box.xml --integrator path --spp 32"
       "scenes/many-lights.ron --integrator restir-di --spp 8"
       "scenes/indirect-room.ron --integrator restir-pt --spp 4"
       "scenes/indirect-room-glass.ron --integrator restir-pt --spp 4 --spatial-rounds 3 --neighbors 4 --radius 3 --candidates 2 --direct path")
[ -f $SPONZA ] && cases+=("$SPONZA --integrator path --spp 4")
[ $# -gt 3 ] && cases=("${@:4}")
for c in "${cases[@]}"; do
  o=(); n=()
  for r in $(seq $R); do
    for which in old new; do
      b=$OLD; [ $which = new ] && b=$NEW
      /usr/bin/time -o /tmp/perf-time -f %U $b render $c --width $W --height $H --threads $T --quiet -o /tmp/perf-$which.exr >/dev/null 2>&1; t=$(tail -1 /tmp/perf-time)
      [ $which = old ] && o+=($t) || n+=($t)
    done
  done
  mo=$(printf "%s\n" "${o[@]}" | sort -n | sed -n "$(( (R+1)/2 ))p"); mn=$(printf "%s\n" "${n[@]}" | sort -n | sed -n "$(( (R+1)/2 ))p")
  echo "$c | old ${o[*]} (median $mo) | new ${n[*]} (median $mn) | new/old $(python3 -c "print(round($mn/$mo,3))")"
done
