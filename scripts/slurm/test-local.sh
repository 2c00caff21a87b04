#!/usr/bin/env bash
# The end-to-end Slurm test (docs/CLUSTER.md): installs Slurm and MUNGE from Debian's packages if
# missing, starts a one-node cluster on this machine (munged, slurmctld, slurmd, all private to a
# temporary directory, on ports 16817/16818), submits the Cornell box as 4 chains (path tracer)
# and as 4 tiles (ReSTIR DI with two rounds of spatial reuse) through submit.sh, waits for the
# merge jobs, checks the merged images against single-process renders (tiles: the same bytes;
# chains: `restir compare` relMSE below 1e-12, float rounding) and stops the daemons.
#
#   scripts/slurm/test-local.sh [path/to/restir]    (default: builds target/release/restir)
#
# Needs root (packages, daemons). Where the cluster cannot be started it says why and exits 1
# under CI=true, 77 (skipped) otherwise. Prints how long it took.
set -euo pipefail
start=$(date +%s)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)

cannot() {
    echo "test-local.sh: cannot run the Slurm test: $*" >&2
    if [[ "${CI:-}" == true ]]; then exit 1; fi
    exit 77
}

[[ $(id -u) -eq 0 ]] || cannot "needs root to install packages and start munged/slurmctld/slurmd"
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
    ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
    echo "== installing slurm-wlm and munge"
    if ! (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge) >/dev/null; then
        cannot "apt-get install slurm-wlm munge failed"
    fi
fi

if [[ $# -ge 1 ]]; then
    restir=$(realpath "$1")
else
    (cd "$repo" && cargo build --release -p restir --quiet)
    restir=$repo/target/release/restir
fi
[[ -x "$restir" ]] || cannot "$restir: no restir binary"

work=$(mktemp -d /tmp/restir-slurm.XXXXXX)
chmod 755 "$work"
mkdir -p "$work/munge" "$work/private" "$work/state" "$work/spool" "$work/log"
chmod 755 "$work/munge"
chmod 700 "$work/private"
export SLURM_CONF=$work/slurm.conf

stop() {
    # Only the daemons this script started, by their pid files.
    for f in "$work/slurmd.pid" "$work/slurmctld.pid" "$work/private/munged.pid"; do
        if [[ -s "$f" ]]; then kill "$(cat "$f")" 2>/dev/null || true; fi
    done
    sleep 1
    if [[ "${KEEP:-}" != 1 ]]; then rm -rf "$work"; fi
}
trap stop EXIT

host=$(hostname -s)
cpus=$(nproc)
echo "== one-node cluster on $host ($cpus CPUs) in $work"
dd if=/dev/urandom of="$work/private/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/private/munge.key"
munged --socket="$work/munge/munge.socket" --key-file="$work/private/munge.key" \
    --log-file="$work/private/munged.log" --pid-file="$work/private/munged.pid" \
    --seed-file="$work/private/munged.seed" ||
    cannot "munged did not start: $(tail -n 3 "$work/private/munged.log" 2>/dev/null)"

cat >"$SLURM_CONF" <<EOF
ClusterName=restirtest
SlurmctldHost=$host
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
PlugStackConfig=$work/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
: >"$work/plugstack.conf"
slurmctld -f "$SLURM_CONF" || cannot "slurmctld did not start: $(tail -n 3 "$work/log/slurmctld.log" 2>/dev/null)"
slurmd -f "$SLURM_CONF" || cannot "slurmd did not start: $(tail -n 3 "$work/log/slurmd.log" 2>/dev/null)"
for _ in $(seq 60); do
    if sinfo -h -o %t 2>/dev/null | grep -qx idle; then break; fi
    sleep 1
done
sinfo -h -o %t | grep -qx idle ||
    cannot "the node did not come up: $(sinfo 2>&1 | tail -n 2); $(tail -n 3 "$work/log/slurmd.log" 2>/dev/null)"
ready=$(date +%s)

scene=$repo/scenes/cornell-box.xml
chains_args=(--width 64 --height 48 --integrator path --seed 3)
# Tiles merge bit for bit only without learning: with it each tile learns from its own region
# (docs/CLUSTER.md, "Learning restarts per part").
tiles_args=(--width 64 --height 64 --integrator restir-di --learn off --radius 4 --spatial-rounds 2 --seed 5)
echo "== submitting 4 chains and 4 tiles"
read -r _ chains_merge < <(RESTIR=$restir "$here/submit.sh" chains 4 "$scene" 16 "$work/chains" "${chains_args[@]}")
read -r _ tiles_merge < <(RESTIR=$restir "$here/submit.sh" tiles 4 "$scene" 2 "$work/tiles" "${tiles_args[@]}")

echo "== single-process references"
"$restir" render "$scene" --spp 16 "${chains_args[@]}" --quiet -o "$work/chains-ref.exr"
"$restir" render "$scene" --spp 2 "${tiles_args[@]}" --quiet -o "$work/tiles-ref.exr"

state() { scontrol -o show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2; }
for _ in $(seq 600); do
    a=$(state "$chains_merge") b=$(state "$tiles_merge")
    if [[ "$a" == COMPLETED && "$b" == COMPLETED ]]; then break; fi
    case "$a $b" in
    *FAILED* | *CANCELLED* | *TIMEOUT* | *NODE_FAIL* | *OUT_OF_ME*)
        echo "merge jobs: chains $a, tiles $b" >&2
        tail -n +1 "$work"/chains/*.out "$work"/tiles/*.out >&2 || true
        exit 1
        ;;
    esac
    sleep 1
done
[[ $(state "$chains_merge") == COMPLETED && $(state "$tiles_merge") == COMPLETED ]] || {
    echo "merge jobs did not finish in 600 s: $(squeue 2>&1)" >&2
    exit 1
}
cat "$work/chains/restir-merge-$chains_merge.out" "$work/tiles/restir-merge-$tiles_merge.out"

echo "== checking the merged images"
cmp "$work/tiles/merged.exr" "$work/tiles-ref.exr"
echo "tiles: merged.exr has the same bytes as the single-process render"
metrics=$("$restir" compare "$work/chains/merged.exr" "$work/chains-ref.exr")
echo "chains: $metrics"
relmse=${metrics#relmse=}
relmse=${relmse%% *}
awk -v r="$relmse" 'BEGIN { exit !(r < 1e-12) }' || {
    echo "chains: relMSE $relmse against the single-process render exceeds float rounding" >&2
    exit 1
}
end=$(date +%s)
echo "slurm test passed in $((end - start)) s (cluster up in $((ready - start)) s, jobs and checks $((end - ready)) s)"
