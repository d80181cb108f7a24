#!/usr/bin/env bash
# A single-node SLURM cluster on this Debian machine, from the distribution's packages
# (munge, slurmctld, slurmd, slurm-client), for trying and testing the SLURM profile.
#
#   sudo scripts/slurm-local.sh up      install (apt-get), configure, start; wait for the node
#   sudo scripts/slurm-local.sh down    cancel jobs, stop the daemons, clear the state
#   scripts/slurm-local.sh status       sinfo and the job records
#
# Root only; refuses with a message on a machine that is not Debian or whose apt sources lack
# the packages. Idempotent: `up` installs nothing twice, rewrites slurm.conf only when it
# changes and starts only daemons that are not running. The node gets the machine's real CPUs
# and memory (`slurmd -C`, minus MEM_MARGIN_MB). No accounting database: Snakemake reads job
# states with `squeue` (the profile's slurm-status-command), which sees finished jobs for
# MinJobAge = 3600 s; SLURM's own record of every finished job (id, name, state, exit code,
# partition, CPUs, TRES, times, comment = the Snakemake rule) goes to
# /var/log/slurm/jobcomp.tsv through JobCompType=jobcomp/script. EnforcePartLimits=ALL
# rejects a job larger than the node at submission instead of leaving it pending.
# Environment: PARTITION (debug), TIMEOUT (60 s), MEM_MARGIN_MB (1024), DEF_MEM_PER_CPU
# (1000), ENFORCE_PART_LIMITS (ALL), JOBCOMP (script | filetxt); down: KEEP_LOGS=1, PURGE=1.
# Tested on Debian 12 (SLURM 22.05, munge 0.5.15) without systemd.
set -euo pipefail

cmd_up() {

PARTITION=${PARTITION:-debug}
TIMEOUT=${TIMEOUT:-60}            # seconds to wait for the node to become idle
MEM_MARGIN_MB=${MEM_MARGIN_MB:-1024}
DEF_MEM_PER_CPU=${DEF_MEM_PER_CPU:-1000}
ENFORCE_PART_LIMITS=${ENFORCE_PART_LIMITS:-ALL}   # NO: oversized jobs pend forever
# filetxt: SLURM writes one line per finished job to /var/log/slurm/jobcomp.log
# script:  /etc/slurm/jobcomp.sh writes /var/log/slurm/jobcomp.tsv, which also has
#          the job Comment (snakemake plugin: rule_<rule>[_wildcards_<w>]) and StdOut
JOBCOMP=${JOBCOMP:-script}
CONF=/etc/slurm/slurm.conf
LOGDIR=/var/log/slurm

die() { echo "slurm-local up: ERROR: $*" >&2; exit 1; }
log() { echo "slurm-local up: $*"; }

[ "$(id -u)" -eq 0 ] || die "must run as root (it installs packages and starts daemons)"
[ -r /etc/debian_version ] || die "not a Debian system (/etc/debian_version missing)"
command -v apt-get >/dev/null || die "apt-get not found"

# --- 1. packages -----------------------------------------------------------
PKGS="munge slurmctld slurmd slurm-client"
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  log "installing:$missing"
  export DEBIAN_FRONTEND=noninteractive
  for p in $missing; do
    if ! apt-cache show "$p" >/dev/null 2>&1; then
      apt-get update -qq || die "apt-get update failed"
      break
    fi
  done
  for p in $missing; do
    apt-cache show "$p" >/dev/null 2>&1 || die "package $p not available from the configured apt sources"
  done
  # policy-rc.d (Docker-style) stops the postinst scripts from starting the
  # daemons; that is fine, we start them ourselves below.
  apt-get install -y -qq --no-install-recommends $missing >/dev/null \
    || die "apt-get install$missing failed"
fi
for b in munged slurmctld slurmd sinfo scontrol; do
  command -v "$b" >/dev/null || die "$b not found after installation"
done

# --- 2. munge ----------------------------------------------------------------
if [ ! -s /etc/munge/munge.key ]; then
  log "creating /etc/munge/munge.key"
  install -d -o munge -g munge -m 0700 /etc/munge
  if command -v mungekey >/dev/null; then
    runuser -u munge -- mungekey --create --keyfile=/etc/munge/munge.key
  else
    dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key status=none
  fi
  chown munge:munge /etc/munge/munge.key; chmod 0400 /etc/munge/munge.key
fi
install -d -o munge -g munge -m 0755 /run/munge
install -d -o munge -g munge -m 0700 /var/lib/munge /var/log/munge

alive() { [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

if alive /run/munge/munged.pid; then
  log "munged already running (pid $(cat /run/munge/munged.pid))"
else
  rm -f /run/munge/munged.pid /run/munge/munge.socket.2 /run/munge/munge.socket.2.lock
  runuser -u munge -- /usr/sbin/munged || die "munged failed to start (see /var/log/munge/munged.log)"
  log "munged started"
fi
for i in $(seq 1 20); do munge -n </dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.25; done
munge -n </dev/null | unmunge >/dev/null 2>&1 || die "munge round trip (munge -n | unmunge) fails"

# --- 3. slurm.conf -------------------------------------------------------------
HOST=$(hostname -s)
getent hosts "$HOST" >/dev/null || die "hostname $HOST does not resolve (add it to /etc/hosts)"
# slurmd -C prints e.g. "NodeName=vm CPUs=2 Boards=1 SocketsPerBoard=1 CoresPerSocket=2 ThreadsPerCore=1 RealMemory=24105"
NODELINE=$(slurmd -C | head -1)
[[ $NODELINE == NodeName=* ]] || die "unexpected 'slurmd -C' output: $NODELINE"
REALMEM=$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$NODELINE")
MEM=$(( REALMEM - MEM_MARGIN_MB ))
[ "$MEM" -gt 0 ] || MEM=$REALMEM
# keep the topology slurmd detects (CPUs, sockets, cores, threads), lower RealMemory
NODEDEF=$(sed -e "s/^NodeName=[^ ]*/NodeName=$HOST/" -e "s/RealMemory=[0-9]*/RealMemory=$MEM/" <<<"$NODELINE")

install -d -m 0755 /etc/slurm
install -d -o slurm -g slurm -m 0755 "$LOGDIR" /var/lib/slurm /var/lib/slurm/slurmctld
install -d -m 0755 /var/lib/slurm/slurmd

case "$JOBCOMP" in
  filetxt) JOBCOMP_LOC=$LOGDIR/jobcomp.log ;;
  script)
    JOBCOMP_LOC=/etc/slurm/jobcomp.sh
    cat > "$JOBCOMP_LOC.new" <<'SCRIPT'
#!/bin/sh
# JobCompType=jobcomp/script hook (written by up.sh): slurmctld runs it as
# SlurmUser once per finished job with JOBID, JOBNAME, JOBSTATE, EXITCODE,
# PARTITION, NODES, PROCS, SUBMIT/START/END (epoch s), LIMIT, ... in the
# environment. Appends one tab-separated line, adding Comment, TRES and StdOut
# from scontrol (the job is still in slurmctld's memory at this point).
OUT=/var/log/slurm/jobcomp.tsv
INFO=$(scontrol show job "$JOBID" 2>/dev/null)
get() { printf '%s\n' "$INFO" | sed -n "s/^ *$1=\(.*[^ ]\) *\$/\1/p" | head -1; }
COMMENT=$(get Comment); STDOUT_PATH=$(get StdOut)
TRES=$(printf '%s\n' "$INFO" | sed -n 's/^ *TRES=\([^ ]*\).*/\1/p' | head -1)
iso() { date -d "@$1" +%Y-%m-%dT%H:%M:%S 2>/dev/null || echo "$1"; }
[ -s "$OUT" ] || printf 'JobId\tJobName\tJobState\tExitCode\tPartition\tNodes\tProcs\tTRES\tSubmit\tStart\tEnd\tLimit\tComment\tStdOut\n' >> "$OUT"
printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' \
  "$JOBID" "$JOBNAME" "$JOBSTATE" "$EXITCODE" "$PARTITION" "$NODES" "$PROCS" "$TRES" \
  "$(iso "$SUBMIT")" "$(iso "$START")" "$(iso "$END")" "$LIMIT" "$COMMENT" "$STDOUT_PATH" >> "$OUT"
SCRIPT
    chmod 0755 "$JOBCOMP_LOC.new"; mv -f "$JOBCOMP_LOC.new" "$JOBCOMP_LOC" ;;
  *) die "JOBCOMP must be filetxt or script, not '$JOBCOMP'" ;;
esac

NEWCONF=$(cat <<EOF
# Written by slurm-local up: single-node SLURM cluster, no slurmdbd, no cgroups.
ClusterName=local
SlurmctldHost=$HOST
SlurmUser=slurm
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
StateSaveLocation=/var/lib/slurm/slurmctld
SlurmdSpoolDir=/var/lib/slurm/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=$LOGDIR/slurmctld.log
SlurmdLogFile=$LOGDIR/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ReturnToService=2
MailProg=/bin/true
# reject at submit time what the partition can never run (e.g. -c 8 on a 2-CPU
# node) instead of leaving it PENDING with Reason=PartitionConfig forever
EnforcePartLimits=${ENFORCE_PART_LIMITS}
# no cgroups: plain /proc based process tracking, no task binding
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
# no accounting database; one text record per finished job instead
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/linux
JobCompType=jobcomp/$JOBCOMP
JobCompLoc=$JOBCOMP_LOC
# keep finished jobs visible to squeue / scontrol show job for an hour
MinJobAge=3600
KillWait=10
InactiveLimit=0
Waittime=0
SlurmctldTimeout=30
SlurmdTimeout=60
$NODEDEF State=UNKNOWN
PartitionName=$PARTITION Nodes=$HOST Default=YES MaxTime=INFINITE State=UP DefMemPerCPU=$DEF_MEM_PER_CPU
EOF
)
if [ -f "$CONF" ] && [ "$(cat "$CONF")" = "$NEWCONF" ]; then
  CONF_CHANGED=0
else
  printf '%s\n' "$NEWCONF" > "$CONF"; chmod 0644 "$CONF"
  CONF_CHANGED=1
  log "wrote $CONF ($NODEDEF)"
fi

# --- 4. slurm daemons --------------------------------------------------------
if [ "$CONF_CHANGED" = 1 ]; then
  # a changed node/partition definition or JobCompType needs a restart, not
  # just 'scontrol reconfigure' (which, with a new JobCompLoc, made slurmctld die)
  for pf in /run/slurmd.pid /run/slurmctld.pid; do
    if alive "$pf"; then log "config changed: stopping $(basename "$pf" .pid)"; kill "$(cat "$pf")"; fi
  done
  for i in $(seq 1 40); do alive /run/slurmd.pid || alive /run/slurmctld.pid || break; sleep 0.25; done
fi
if alive /run/slurmctld.pid; then
  log "slurmctld already running (pid $(cat /run/slurmctld.pid))"
else
  # slurmctld drops to SlurmUser=slurm itself
  /usr/sbin/slurmctld || die "slurmctld failed to start (see $LOGDIR/slurmctld.log)"
  log "slurmctld started"
fi
if alive /run/slurmd.pid; then
  log "slurmd already running (pid $(cat /run/slurmd.pid))"
else
  /usr/sbin/slurmd || die "slurmd failed to start (see $LOGDIR/slurmd.log)"
  log "slurmd started"
fi

# --- 5. wait for the node ------------------------------------------------------
deadline=$(( $(date +%s) + TIMEOUT ))
state=""
while :; do
  state=$(sinfo -h -N -n "$HOST" -o '%T' 2>/dev/null | head -1 || true)
  case "$state" in
    idle|mixed|allocated) break ;;
    drain*|down*|fail*)
      # a node left DOWN by an earlier run (e.g. unexpected reboot)
      scontrol update NodeName="$HOST" State=RESUME 2>/dev/null || true ;;
  esac
  if [ "$(date +%s)" -ge "$deadline" ]; then
    echo "slurm-local up: ERROR: node $HOST not idle after ${TIMEOUT}s (state: '${state:-no answer from slurmctld}')" >&2
    sinfo -R 2>&1 | sed 's/^/  sinfo -R: /' >&2 || true
    tail -n 5 "$LOGDIR/slurmctld.log" "$LOGDIR/slurmd.log" >&2 2>/dev/null || true
    exit 1
  fi
  sleep 1
done
log "cluster up: node $HOST is $state"
sinfo
}

cmd_down() {
set +e
[ "$(id -u)" -eq 0 ] || { echo "slurm-local down: ERROR: must run as root" >&2; exit 1; }

alive() { [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }
stop() {  # stop <name> <pidfile>
  local name=$1 pf=$2 pid
  if alive "$pf"; then
    pid=$(cat "$pf")
    kill "$pid"
    for i in $(seq 1 40); do kill -0 "$pid" 2>/dev/null || break; sleep 0.25; done
    if kill -0 "$pid" 2>/dev/null; then kill -9 "$pid"; echo "slurm-local down: $name ($pid) killed"; else echo "slurm-local down: $name ($pid) stopped"; fi
  else
    echo "slurm-local down: $name not running"
  fi
  rm -f "$pf"
}

# running jobs first, so no job steps outlive slurmd
if alive /run/slurmctld.pid && command -v scancel >/dev/null; then
  ids=$(squeue -h -t PENDING,RUNNING,SUSPENDED,CONFIGURING,COMPLETING -o %A 2>/dev/null || true)
  [ -z "$ids" ] || scancel $ids 2>/dev/null || true
  sleep 1
fi
stop slurmd /run/slurmd.pid
stop slurmctld /run/slurmctld.pid
stop munged /run/munge/munged.pid

rm -rf /var/lib/slurm/slurmctld/* /var/lib/slurm/slurmd/*
[ "${KEEP_LOGS:-0}" = 1 ] || rm -f /var/log/slurm/*.log /var/log/slurm/*.tsv
[ -f /etc/slurm/slurm.conf ] && mv -f /etc/slurm/slurm.conf /etc/slurm/slurm.conf.last
if [ "${PURGE:-0}" = 1 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq slurmctld slurmd slurm-client slurm-wlm-basic-plugins munge libmunge2 >/dev/null \
    && echo "slurm-local down: packages purged" || echo "slurm-local down: WARNING: apt-get purge failed" >&2
fi
echo "slurm-local down: cluster down, state cleared"
}

cmd_status() {
  command -v sinfo >/dev/null || { echo "slurm-local status: sinfo not installed (run: sudo $0 up)" >&2; exit 1; }
  sinfo
  [ -s /var/log/slurm/jobcomp.tsv ] && column -t -s $'\t' /var/log/slurm/jobcomp.tsv | tail -n 20
  return 0
}

case "${1:-}" in
  up) cmd_up ;;
  down) cmd_down ;;
  status) cmd_status ;;
  *) echo "usage: $0 up|down|status" >&2; exit 2 ;;
esac
