#!/usr/bin/env bash
# Submits a split render to Slurm (docs/CLUSTER.md): an array of PARTS tasks (render-array.sbatch)
# and a merge job that depends on all of them (--dependency=afterok). Prints the two job ids.
#
#   scripts/slurm/submit.sh MODE PARTS SCENE SPP OUT_DIR [restir render options...]
#
# MODE is chains or tiles; tiles need --width W --height H among the options (the film is cut
# into PARTS bands of rows). RESTIR (default: restir on PATH) names the binary; SBATCH_ARGS adds
# sbatch options (partition, account, time, --cpus-per-task) to both jobs. The merged image is
# OUT_DIR/merged.exr.
set -euo pipefail
if [[ $# -lt 5 ]]; then
    sed -n '2,11p' "$0" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
mode=$1 parts=$2 scene=$3 spp=$4 out=$5
shift 5
width='' height='' rest=()
while [[ $# -gt 0 ]]; do
    case "$1" in
    --width) width=$2; shift 2 ;;
    --height) height=$2; shift 2 ;;
    *) rest+=("$1"); shift ;;
    esac
done
mkdir -p "$out"
scene=$(realpath "$scene")
out=$(cd "$out" && pwd)
restir=$(command -v "${RESTIR:-restir}") || { echo "RESTIR=${RESTIR:-restir}: not found" >&2; exit 2; }
export RESTIR=$restir SCENE=$scene OUT_DIR=$out MODE=$mode PARTS=$parts SPP=$spp WIDTH=$width \
    HEIGHT=$height RENDER_ARGS="${rest[*]:-}" MERGED=$out/merged.exr
# shellcheck disable=SC2086 # SBATCH_ARGS is a list of options
array=$(sbatch --parsable ${SBATCH_ARGS:-} --chdir="$out" --export=ALL \
    --array="0-$((parts - 1))" "$here/render-array.sbatch")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_ARGS:-} --chdir="$out" --export=ALL \
    --dependency="afterok:$array" "$here/merge.sbatch")
echo "$array ${merge%%;*}"
