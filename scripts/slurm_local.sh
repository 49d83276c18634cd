#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the Slurm backend's tests
# (`demx campaign --slurm`, `demx sweep --slurm`): munge for authentication,
# slurmctld as controller and slurmd as the one compute node, both on the
# local host, no cgroups (proctrack/linuxproc, task/none) so that it starts
# inside a container as well as on a workstation.
#
#   bash scripts/slurm_local.sh          start it (idempotent: a running cluster is kept)
#   bash scripts/slurm_local.sh stop     stop the daemons
#
# Installs Debian's slurm-wlm and munge when sbatch is missing. Runs as root
# (the daemons' SlurmUser is the calling user). The configuration and state
# live under /var/lib/demx-slurm; /etc/slurm/slurm.conf is written only when
# it is absent or was written by this script (a real cluster's is left alone).
set -euo pipefail

state=/var/lib/demx-slurm
conf=/etc/slurm/slurm.conf
marker="# written by demx scripts/slurm_local.sh"

stop() {
    pkill -x slurmd 2>/dev/null || true
    pkill -x slurmctld 2>/dev/null || true
}

if [ "${1:-}" = stop ]; then
    stop
    exit 0
fi

if ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "slurm_local.sh: sbatch or munged missing and not root: install slurm-wlm and munge" >&2
        exit 1
    fi
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q slurm-wlm munge >/dev/null
fi

if [ -f "$conf" ] && ! grep -qF "$marker" "$conf"; then
    echo "slurm_local.sh: $conf exists and is not ours; using the cluster it describes" >&2
    exit 0
fi

host=$(hostname -s)
cpus=$(nproc)
mem_mb=$(awk '/^MemTotal:/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
user=$(id -un)
mkdir -p "$state/ctld" "$state/d" /var/log/slurm /etc/slurm

# munge: its key comes with the package; the daemon wants its run folder
if ! pgrep -x munged >/dev/null; then
    mkdir -p /run/munge /var/log/munge /var/lib/munge
    chown munge:munge /run/munge /var/log/munge /var/lib/munge 2>/dev/null || true
    if [ ! -s /etc/munge/munge.key ]; then
        mungekey --create --keyfile=/etc/munge/munge.key 2>/dev/null || dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 2>/dev/null
        chown munge:munge /etc/munge/munge.key
        chmod 400 /etc/munge/munge.key
    fi
    if id munge >/dev/null 2>&1; then
        su -s /bin/sh munge -c munged || munged --force
    else
        munged --force
    fi
fi

new=$(mktemp)
cat > "$new" <<CONF
$marker
ClusterName=demx
SlurmctldHost=$host
SlurmUser=$user
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/d
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
# a task at its time limit gets SIGTERM (or the --signal the script asks
# for), then this many seconds to checkpoint before SIGKILL
KillWait=30
MinJobAge=3600
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
if ! cmp -s "$new" "$conf" 2>/dev/null; then
    stop
    cp "$new" "$conf"
fi
rm -f "$new"

pgrep -x slurmctld >/dev/null || slurmctld
pgrep -x slurmd >/dev/null || slurmd

# wait for the node to take jobs
for _ in $(seq 1 60); do
    state_now=$(sinfo -h -n "$host" -o %t 2>/dev/null || true)
    case "$state_now" in
        idle*|mix*|alloc*) echo "slurm_local.sh: one-node cluster up ($host, $cpus CPUs)"; exit 0 ;;
        down*|drain*) scontrol update nodename="$host" state=resume 2>/dev/null || true ;;
    esac
    sleep 1
done
echo "slurm_local.sh: the node did not come up; see /var/log/slurm/" >&2
sinfo >&2 || true
exit 1
