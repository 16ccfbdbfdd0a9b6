#!/usr/bin/env bash
# A single-node Slurm cluster on 127.0.0.1, without systemd, for the campaign tests and for
# trying `campaign slurm` on one machine.
#
#   bash scripts/slurm-local.sh start   # installs the packages if missing, starts munged,
#                                       # slurmctld and slurmd; prints the folder and the
#                                       # line to export (SLURM_CONF)
#   bash scripts/slurm-local.sh stop    # stops the three daemons by their PIDs
#   bash scripts/slurm-local.sh status
#
# Configuration, state, logs and PID files live in one folder ($SLURM_LOCAL_DIR, default
# target/slurm-local). Authentication is auth/munge with a key made for the folder (with
# auth/none the job port would accept anyone's requests). Ports: $SLURM_LOCAL_PORT (default
# 16817) for slurmctld and the next one for slurmd.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/apt-install.sh
action="${1:-}"
dir="$(realpath -m "${SLURM_LOCAL_DIR:-target/slurm-local}")"
port="${SLURM_LOCAL_PORT:-16817}"
conf="$dir/slurm/slurm.conf"

install_packages() {
    apt_install_missing slurm-local slurmctld slurmd slurm-client munge
}

alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

# stops the daemon whose PID is in file $1 (TERM, then KILL after 10 s)
stop_pid() {
    local file="$1" name="$2" pid
    [ -f "$file" ] || return 0
    pid="$(cat "$file")"
    if kill -0 "$pid" 2>/dev/null; then
        kill "$pid"
        for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        if kill -0 "$pid" 2>/dev/null; then
            echo "slurm-local: $name ($pid) ignored TERM, killing" >&2
            kill -9 "$pid"
        fi
    fi
    rm -f "$file"
    echo "slurm-local: stopped $name ($pid)"
}

case "$action" in
start)
    if [ "$(id -u)" -ne 0 ]; then
        echo "slurm-local: start needs root (munged runs as user munge, slurmd as root)" >&2
        exit 1
    fi
    install_packages
    if alive "$dir/slurm/slurmctld.pid" || alive "$dir/slurm/slurmd.pid" || alive "$dir/munge/munged.pid"; then
        echo "slurm-local: already running in $dir (stop it first)" >&2
        exit 1
    fi
    mkdir -p "$dir"/{munge,munge-socket,slurm/state,slurm/spool}
    chmod 755 "$dir" "$dir/munge-socket"
    chmod 700 "$dir/munge"
    chown munge:munge "$dir/munge" "$dir/munge-socket"
    key="$dir/munge/munge.key"
    if [ ! -s "$key" ]; then
        rm -f "$key"
        runuser -u munge -- mungekey -c -k "$key"
    fi
    socket="$dir/munge-socket/munge.socket.2"
    runuser -u munge -- munged --force --socket="$socket" --key-file="$key" \
        --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed"
    cpus="$(nproc)"
    cat > "$conf" <<EOF
ClusterName=nigel-local
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=sched_min_interval=0,batch_sched_delay=0
StateSaveLocation=$dir/slurm/state
SlurmdSpoolDir=$dir/slurm/spool
SlurmctldPidFile=$dir/slurm/slurmctld.pid
SlurmdPidFile=$dir/slurm/slurmd.pid
SlurmctldLogFile=$dir/slurm/slurmctld.log
SlurmdLogFile=$dir/slurm/slurmd.log
MpiDefault=none
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MinJobAge=600
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF="$conf"
    slurmctld -f "$conf"
    slurmd -f "$conf" -N localhost
    for _ in $(seq 100); do
        state="$(sinfo -h -o %t 2>/dev/null || true)"
        [ "$state" = "idle" ] && break
        sleep 0.1
    done
    if [ "$state" != "idle" ]; then
        echo "slurm-local: the node did not reach idle (state '$state'); logs in $dir/slurm" >&2
        exit 1
    fi
    echo "slurm-local: running in $dir (munged $(cat "$dir/munge/munged.pid"), slurmctld $(cat "$dir/slurm/slurmctld.pid"), slurmd $(cat "$dir/slurm/slurmd.pid"))"
    echo "export SLURM_CONF=$conf"
    ;;
stop)
    stop_pid "$dir/slurm/slurmd.pid" slurmd
    stop_pid "$dir/slurm/slurmctld.pid" slurmctld
    stop_pid "$dir/munge/munged.pid" munged
    ;;
status)
    for f in "$dir/munge/munged.pid" "$dir/slurm/slurmctld.pid" "$dir/slurm/slurmd.pid"; do
        if alive "$f"; then echo "running: $(basename "$f" .pid) $(cat "$f")"; else echo "stopped: $(basename "$f" .pid)"; fi
    done
    echo "export SLURM_CONF=$conf"
    ;;
*)
    echo "usage: $0 start|stop|status" >&2
    exit 2
    ;;
esac
