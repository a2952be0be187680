#!/bin/bash
# Start/stop a throw-away one-node Slurm cluster (slurmctld + slurmd + munged)
# whose config, keys, sockets, state, logs and pid files all live under DIR,
# so a CI machine's /etc/slurm, /etc/munge and /run/munge stay untouched.
#
#   eval "$(slurm_one_node.sh start DIR)"   # prints: export SLURM_CONF=DIR/slurm.conf
#   slurm_one_node.sh stop DIR
#
# Needs root (SlurmUser=root keeps ownership checks trivial) and Debian
# packages slurmctld slurmd slurm-client munge. Uses TCP ports 6817/6818, so no
# other slurmctld/slurmd may run on the machine.
set -euo pipefail

usage() { echo "usage: $0 start|stop DIR" >&2; exit 2; }
[[ $# -eq 2 ]] || usage
cmd=$1
# Absolute path: daemons chdir, and the path ends up in slurm.conf.
dir=$(realpath -m -- "$2")
# Daemons live in /usr/sbin, which a non-login root shell may lack on PATH.
export PATH="$PATH:/usr/sbin:/sbin"

log() { echo "slurm_one_node: $*" >&2; }

# Pid from DIR/run/NAME.pid if that process is alive and has the expected name,
# so a stale pid file (or a recycled pid) never makes us hit another process.
daemon_pid() { # name
  local pid
  pid=$(cat "$dir/run/$1.pid" 2>/dev/null) || return 1
  [[ $pid =~ ^[0-9]+$ ]] || return 1
  # comm is cut at 15 chars; Debian's real binaries are slurmd-wlm etc.
  [[ $(cat "/proc/$pid/comm" 2>/dev/null) == "$1"* ]] && echo "$pid"
}

# SIGTERM the named daemons together, wait up to 30 s, then SIGKILL.
stop_daemons() { # name...
  local name pid pids=() i k
  for name; do
    if pid=$(daemon_pid "$name"); then kill -TERM "$pid" 2>/dev/null && pids+=("$pid"); fi
  done
  for ((i = 0; i < 300 && ${#pids[@]}; i++)); do
    for k in "${!pids[@]}"; do kill -0 "${pids[k]}" 2>/dev/null || unset "pids[k]"; done
    sleep 0.1
  done
  for pid in "${pids[@]}"; do log "pid $pid ignored SIGTERM, killing"; kill -KILL "$pid" 2>/dev/null || true; done
}

do_stop() {
  # Cancel jobs first: slurmstepd and job processes outlive slurmd otherwise.
  local i
  if daemon_pid slurmctld >/dev/null && daemon_pid slurmd >/dev/null; then
    export SLURM_CONF=$dir/slurm.conf
    scancel --partition=ci 2>/dev/null || true
    for ((i = 0; i < 60; i++)); do
      [[ -z $(squeue -h -o %i 2>/dev/null) ]] && break
      sleep 0.5
    done
  fi
  # munged last: the slurm daemons authenticate through it while shutting down.
  stop_daemons slurmd slurmctld
  stop_daemons munged
}

do_start() {
  local b pkg
  for b in slurmctld:slurmctld slurmd:slurmd sbatch:slurm-client sinfo:slurm-client munged:munge; do
    pkg=${b#*:}; b=${b%%:*}
    command -v "$b" >/dev/null || { log "'$b' not found: apt-get install $pkg"; exit 1; }
  done
  [[ $(id -u) -eq 0 ]] || { log "must run as root (SlurmUser=root)"; exit 1; }
  # Refuse a used DIR: stale state/pid files would confuse start and stop.
  if [[ -e $dir ]] && [[ -n $(ls -A "$dir") ]]; then log "$dir exists and is not empty"; exit 1; fi

  # Another slurmctld/slurmd would answer our clients (and fail munge auth),
  # so fail fast instead of timing out.
  local port
  for port in 6817 6818; do
    if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
      log "port $port is already in use (another Slurm running?)"; exit 1
    fi
  done

  # munged refuses group/world-writable dirs for its key, socket and logs.
  mkdir -p "$dir"/{etc,run,log,state,spool}
  chmod 0755 "$dir" "$dir"/{etc,run,log,state,spool}

  dd if=/dev/urandom of="$dir/etc/munge.key" bs=1024 count=1 status=none
  chmod 0400 "$dir/etc/munge.key"   # munged rejects a key readable by others

  # slurmd must find a NodeName equal to its short hostname; NodeAddr pins the
  # address so a CI host whose name does not resolve still works.
  local host hw cpus mem
  host=$(hostname -s)
  # Declare the topology and memory slurmd itself detects (or less): anything
  # more drains the node ("Low socket*core*thread count", "Low RealMemory").
  hw=$(slurmd -C | head -n1)
  cpus=$(grep -o 'CPUs=.*ThreadsPerCore=[0-9]*' <<<"$hw")
  mem=$(grep -o 'RealMemory=[0-9]*' <<<"$hw" | cut -d= -f2)
  mem=$((mem > 1024 ? 1024 : mem))  # modest: memory is not scheduled (CR_CPU)
  : >"$dir/etc/plugstack.conf"  # keep the host's SPANK plugins out

  cat >"$dir/slurm.conf" <<EOF
ClusterName=ci
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
# Point slurm (daemons, clients and slurmstepd) at our private munged.
AuthInfo=socket=$dir/run/munge.socket
# No cgroups: CI containers often lack a writable cgroup tree.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
# CR_CPU, not CR_Core: on SMT hosts CR_Core gives each job a whole core and
# halves how many single-CPU array tasks run at once.
SelectTypeParameters=CR_CPU
PlugStackConfig=$dir/etc/plugstack.conf
# Keep finished job records (default: a day). sbatch --wait (22.05) takes the
# exit code of every array task at its final poll, so a task record purged
# before the whole array ends turns a failed task into exit 0. Cost: sbatch
# --wait polls after 2, 8, 32, 32... s. MinJobAge<=5 gives 2 s polls but is
# only safe without arrays (Slurm clamps it to >=2).
MinJobAge=${SLURM_ONE_NODE_MIN_JOB_AGE:-86400}
MaxJobCount=100000
# Start queued batch jobs as soon as resources free up (default delay 3 s).
SchedulerParameters=batch_sched_delay=0
# Quick scancel at stop; a node marked DOWN revives when slurmd re-registers.
KillWait=5
ReturnToService=2
# Debian's default /usr/bin/mail is usually absent.
MailProg=/bin/true
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
NodeName=$host NodeAddr=127.0.0.1 $cpus RealMemory=$mem State=UNKNOWN
PartitionName=ci Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF=$dir/slurm.conf

  # If anything below fails, leave no daemons behind.
  trap 'log "start failed; logs in $dir/log"; do_stop' EXIT

  # Explicit paths for every munged file: its defaults are /etc/munge,
  # /run/munge, /var/log/munge and /var/lib/munge. --force turns munged's
  # "every ancestor of the socket must be world-searchable" error into a
  # warning (mktemp -d makes 0700 dirs); only root can then reach the socket.
  # Detach stdio so `$(slurm_one_node.sh start ...)` does not hang on daemons.
  {
    munged --force --socket="$dir/run/munge.socket" --key-file="$dir/etc/munge.key" \
      --pid-file="$dir/run/munged.pid" --log-file="$dir/log/munged.log" \
      --seed-file="$dir/run/munged.seed"
    slurmctld -f "$SLURM_CONF"
    slurmd -f "$SLURM_CONF"
  } </dev/null >>"$dir/log/daemons.out" 2>&1

  # Ready = node idle and slurmctld's first scheduling pass done (~3 s after
  # start); until then submitted jobs just sit pending.
  local t0=$SECONDS state='' cycles d why=''
  while ((SECONDS - t0 < 60)); do
    state=$(sinfo -h -N -n "$host" -o %T 2>/dev/null || true)
    cycles=$(sdiag 2>/dev/null | awk '/Main schedule/ {m=1} m && /Total cycles:/ {print $3; exit}' || true)
    if [[ $state == idle && ${cycles:-0} -gt 0 ]]; then break; fi
    # A daemon that died (bad config, port taken) will not come back.
    for d in slurmctld slurmd; do
      if [[ -s $dir/run/$d.pid ]] && ! kill -0 "$(<"$dir/run/$d.pid")" 2>/dev/null; then why="$d died"; fi
    done
    if [[ -n $why ]]; then break; fi
    sleep 0.5
  done
  if [[ $state != idle || ${cycles:-0} -eq 0 ]]; then
    log "node $host not ready (${why:-timeout after 60 s}; state '${state:-unreachable}')"
    tail -n 20 "$dir"/log/*.log >&2 || true
    exit 1  # the EXIT trap stops what did start
  fi
  trap - EXIT
  echo "export SLURM_CONF=$SLURM_CONF"
}

case $cmd in
  start) do_start ;;
  stop) do_stop ;;
  *) usage ;;
esac
