#!/usr/bin/env bash
# Stops what deploy/local/start.sh started in RUN_DIR (default /tmp/splinegrid-local), by the pid
# files it wrote, in this order:
#   1. nginx gets SIGQUIT (its graceful stop: closes the listener, lets calls in flight finish,
#      bounded by worker_shutdown_timeout) and the replicas SIGTERM at the same time (each goes
#      NOT_SERVING, stops accepting calls, gives in-flight calls --shutdown_grace, exits 0);
#   2. after SHUTDOWN_GRACE + 5 s whatever is left gets SIGKILL;
#   3. then redis-server gets SIGTERM (it fsyncs the AOF and exits), SIGKILL after 10 s.
# A pid file whose process is gone, or is no longer the program start.sh started, is removed
# without signalling anything. Redis data in RUN_DIR/redis is kept.
#
# Then it checks the ports start.sh recorded in RUN_DIR/ports. A port that still has a listener
# (a process restarted by hand without its RUN_DIR/cmd script, another topology on the same
# ports, an nginx worker left by a SIGKILLed master) is reported on stderr with the process
# listening there, and stop.sh exits 1. It never signals a process that is not in its pid files.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=deploy/local/common.sh
. "$here/common.sh"
RUN_DIR=${RUN_DIR:-/tmp/splinegrid-local}
SHUTDOWN_GRACE=${SHUTDOWN_GRACE:-8s}
grace=${SHUTDOWN_GRACE%s}; [[ $grace =~ ^[0-9]+$ ]] || grace=10

[[ -d $RUN_DIR ]] || { echo "stop.sh: no $RUN_DIR, nothing to stop"; exit 0; }

# pid of pidfile $1 if it is alive and its command line contains $2, else empty.
live_pid() {
  local pidfile=$1 expect=$2 pid
  [[ -s $pidfile ]] || return 0
  pid=$(<"$pidfile")
  if [[ $pid =~ ^[0-9]+$ ]] && kill -0 "$pid" 2>/dev/null &&
     tr '\0' ' ' 2>/dev/null <"/proc/$pid/cmdline" | grep -q -- "$expect"; then
    echo "$pid"
  else
    rm -f "$pidfile"
  fi
}

# Waits up to $1 seconds for the pids in the rest of the arguments; SIGKILLs what is left.
wait_or_kill() {
  local timeout=$1; shift
  local deadline=$(( $(date +%s) + timeout )) pid alive
  while :; do
    alive=()
    for pid in "$@"; do kill -0 "$pid" 2>/dev/null && alive+=("$pid"); done
    ((${#alive[@]} == 0)) && return 0
    if (( $(date +%s) >= deadline )); then
      echo "stop.sh: SIGKILL to ${alive[*]} (still running after ${timeout}s)"
      kill -KILL "${alive[@]}" 2>/dev/null
      return 1
    fi
    sleep 0.2
  done
}

t0=$(date +%s.%N)
first=()
if pid=$(live_pid "$RUN_DIR/nginx.pid" nginx) && [[ -n $pid ]]; then
  kill -QUIT "$pid" && first+=("$pid") && echo "stop.sh: nginx ($pid) SIGQUIT"
fi
for pidfile in "$RUN_DIR"/splinegrid-*.pid; do
  [[ -e $pidfile ]] || continue
  if pid=$(live_pid "$pidfile" serve) && [[ -n $pid ]]; then
    kill -TERM "$pid" && first+=("$pid") && echo "stop.sh: $(basename "$pidfile" .pid) ($pid) SIGTERM"
  fi
done
status=0
if ((${#first[@]})); then wait_or_kill $((grace + 5)) "${first[@]}" || status=1; fi
rm -f "$RUN_DIR/nginx.pid" "$RUN_DIR"/splinegrid-*.pid "$RUN_DIR/address"

if pid=$(live_pid "$RUN_DIR/redis.pid" redis-server) && [[ -n $pid ]]; then
  kill -TERM "$pid" && echo "stop.sh: redis-server ($pid) SIGTERM"
  wait_or_kill 10 "$pid" || status=1
fi
rm -f "$RUN_DIR/redis.pid"

# Anything still listening on the topology's ports was not stopped here.
leftover=()
if [[ -s $RUN_DIR/ports ]]; then
  while read -r name port; do
    [[ $port =~ ^[0-9]+$ ]] || continue
    # (a listener of a process that has just exited may take a moment to close)
    for ((try = 0; try < 10; try++)); do port_listening "$port" || continue 2; sleep 0.2; done
    echo "stop.sh: port $port ($name) still has a listener, which stop.sh did not stop" \
         "(it signals only the pids in $RUN_DIR/*.pid): $(port_users "$port")" >&2
    leftover+=("$port")
  done <"$RUN_DIR/ports"
else
  echo "stop.sh: no $RUN_DIR/ports (written by start.sh), so the ports were not checked" >&2
fi
took=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
if ((${#leftover[@]})); then
  echo "stop.sh: NOT stopped: port(s) ${leftover[*]} of RUN_DIR=$RUN_DIR still listening (see above);" \
       "stop that process yourself if it belongs to this topology" >&2
  exit 1
fi
echo "stop.sh: stopped in $took s$( ((status)) && echo ', some processes needed SIGKILL')"
exit $status
