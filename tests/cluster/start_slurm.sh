#!/usr/bin/env bash
# Start a one-node SLURM cluster on localhost (munged, slurmctld, slurmd from Debian's slurm-wlm and munge
# packages) unless it already runs. Exits 0 once `sinfo` answers with the node idle, printing one line that
# names its partition and node; otherwise prints one line saying why and exits 1.
# State and logs live in $PARKSTEER_SLURM_DIR (default /tmp/parksteer-slurm). The configuration is written
# there from slurm.conf.in and linked from /etc/slurm/slurm.conf, the default path: SLURM_CONF cannot point
# elsewhere, since the executor plugin's job step (snakemake-executor-plugin-slurm-jobstep) drops every
# SLURM_* variable before its nested srun, which then finds no configuration.
set -uo pipefail

here=$(cd "$(dirname "$0")" && pwd)
state=${PARKSTEER_SLURM_DIR:-/tmp/parksteer-slurm}
conf=$state/slurm.conf
etc_conf=/etc/slurm/slurm.conf
unset SLURM_CONF
export PATH=$PATH:/usr/sbin:/sbin  # the daemons, for a caller whose PATH lacks sbin
mkdir -p "$state" || exit 1

fail() { echo "start_slurm.sh: $*" >&2; exit 1; }

answers() {  # the partition is up and its node idle (or running jobs)
    local node_state
    node_state=$(timeout 10 sinfo --noheader --partition=debug --format=%t 2>/dev/null) || return 1
    [[ $node_state =~ ^(idle|mix|alloc|comp)$ ]]
}

for tool in munged munge unmunge slurmctld slurmd sinfo sbatch squeue srun scontrol; do
    command -v "$tool" >/dev/null || fail "$tool not found: install Debian's slurm-wlm and munge packages"
done
up() { echo "slurm cluster up: partition debug, node $(hostname -s) ($(readlink -f $etc_conf))"; exit 0; }
if [[ $(readlink -f $etc_conf) == "$conf" ]] && answers; then up; fi
[[ $(id -u) == 0 ]] || fail "starting slurmd needs root (it launches jobs as their owner); run as root"
if [[ -e $etc_conf || -L $etc_conf ]] && [[ $(readlink -f $etc_conf) != "$conf" ]]; then
    fail "$etc_conf exists and is not this test cluster's: not replacing it"
fi

# munge: the key comes with the package (its postinst); the daemon runs as user munge, as Debian's service does.
if ! timeout 10 munge -n 2>/dev/null | timeout 10 unmunge >/dev/null 2>&1; then
    [[ -s /etc/munge/munge.key ]] || mungekey --create >/dev/null 2>&1 \
        || fail "no /etc/munge/munge.key and mungekey cannot create one"
    chown munge:munge /etc/munge/munge.key && chmod 600 /etc/munge/munge.key
    mkdir -p /run/munge /var/log/munge /var/lib/munge
    chown munge:munge /run/munge /var/log/munge /var/lib/munge
    runuser -u munge -- munged >"$state/munged.out" 2>&1 || fail "munged did not start: $(tail -n 1 "$state/munged.out")"
    for _ in $(seq 20); do
        timeout 10 munge -n 2>/dev/null | timeout 10 unmunge >/dev/null 2>&1 && break
        sleep 0.5
    done
    timeout 10 munge -n 2>/dev/null | timeout 10 unmunge >/dev/null 2>&1 || fail "munged started but munge -n | unmunge fails"
fi

# slurm.conf for this machine: node named as `hostname -s`, its CPUs and memory as slurmd -C reports them.
node=$(hostname -s)
read -r cpus memory_mb < <(slurmd -C 2>/dev/null \
    | sed -n 's/.*CPUs=\([0-9]*\).*RealMemory=\([0-9]*\).*/\1 \2/p' | head -n 1)
[[ -n ${cpus:-} && -n ${memory_mb:-} ]] || fail "slurmd -C did not report CPUs and RealMemory"
mkdir -p "$state/ctld" "$state/d"
sed -e "s|@NODE@|$node|g" -e "s|@CPUS@|$cpus|g" -e "s|@MEMORY_MB@|$memory_mb|g" -e "s|@STATE@|$state|g" \
    "$here/slurm.conf.in" >"$conf.new"
mv "$conf.new" "$conf"
mkdir -p /etc/slurm && ln -sfn "$conf" "$etc_conf"

running() {  # $1 runs under the pid in its pid file (not another process that reuses a stale pid)
    local pid
    pid=$(cat "$state/$1.pid" 2>/dev/null) && [[ $(cat "/proc/$pid/comm" 2>/dev/null) == "$1" ]]
}
if ! running slurmctld; then
    slurmctld -f "$conf" >>"$state/start.out" 2>&1 || fail "slurmctld did not start: $(tail -n 1 "$state/slurmctld.log" 2>/dev/null)"
fi
if ! running slurmd; then
    slurmd -f "$conf" >>"$state/start.out" 2>&1 || fail "slurmd did not start: $(tail -n 1 "$state/slurmd.log" 2>/dev/null)"
fi

for i in $(seq 60); do
    if answers; then up; fi
    # a node that was down when slurmctld last saw it (an earlier run's) comes back on request
    if (( i % 10 == 5 )); then scontrol update nodename="$node" state=resume >/dev/null 2>&1; fi
    sleep 0.5
done
fail "the cluster did not answer sinfo with node $node idle within 30 s: $(timeout 10 sinfo --noheader 2>&1 | head -n 1); see $state/slurmctld.log"
