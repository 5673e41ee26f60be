#!/usr/bin/env bash
# Starts the whole splinegrid topology as plain processes on loopback, in the background:
#
#     redis-server (AOF, appendfsync always)  <-  N x splinegrid serve --store=redis://...  <-  nginx
#
#   deploy/local/start.sh          # then: build/splinegrid --server=127.0.0.1:50051 list
#   deploy/local/stop.sh           # same environment (RUN_DIR) as start.sh
#
# Settings (environment):
#   RUN_DIR       where configs, pid files, logs and Redis data go (default /tmp/splinegrid-local).
#                 Redis data is kept across stop/start: a second start serves the same grids.
#   REPLICAS      number of splinegrid replicas (default 3)
#   NGINX_PORT    the port clients use (default 50051)
#   REPLICA_PORT  first replica port; replica i listens on REPLICA_PORT+i (default 50061)
#   REDIS_PORT    (default 16379)
#   SPLINEGRID    the splinegrid binary (default: build/splinegrid of this repository)
#   STORE         redis (default) or memory: memory starts the replicas without Redis state
#                 sharing (each has its own grids; only for checking the plumbing)
#   SHUTDOWN_GRACE  --shutdown_grace of the replicas (default 8s); stop.sh waits for it
#   SERVE_ARGS    more serve flags, e.g. "--threads=1 --memory_budget_mb=1024" (the same for every
#                 replica: give per-replica ports below, not in here)
#   METRICS_PORT  first metrics port: replica i serves Prometheus metrics on 127.0.0.1:METRICS_PORT+i
#                 (--metrics_address; one scrape target per replica). Default: none
#   START_TIMEOUT seconds to wait for each process to become ready (default 30)
#   REDIS_SERVER, NGINX  the binaries (default: redis-server, nginx from PATH, /usr/sbin)
#
# Refuses (exit 1, nothing started) when one of its ports already has a listener on 127.0.0.1:
# REDIS_PORT (STORE=redis), REPLICA_PORT..REPLICA_PORT+REPLICAS-1, NGINX_PORT. A process counts
# as ready only while it is alive and (as far as `ss -ltnp` can tell) is the one listening on its
# port.
#
# Writes to RUN_DIR: the ports (RUN_DIR/ports, which stop.sh checks), one pid file and log per
# process, and the command that starts each process in the background exactly as start.sh did
# (RUN_DIR/cmd/redis.sh, splinegrid-I.sh, nginx.sh; rerun one to restart that process by hand;
# it writes the pid file, so stop.sh stops it too).
#
# Prints the address to use on the last line: SPLINEGRID_SERVER=127.0.0.1:NGINX_PORT (also in
# RUN_DIR/address). On any failure it stops what it started, prints the failing log and exits 1.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
# shellcheck source=deploy/local/common.sh
. "$here/common.sh"

RUN_DIR=${RUN_DIR:-/tmp/splinegrid-local}
REPLICAS=${REPLICAS:-3}
NGINX_PORT=${NGINX_PORT:-50051}
REPLICA_PORT=${REPLICA_PORT:-50061}
REDIS_PORT=${REDIS_PORT:-16379}
SPLINEGRID=${SPLINEGRID:-$repo/build/splinegrid}
STORE=${STORE:-redis}
SHUTDOWN_GRACE=${SHUTDOWN_GRACE:-8s}
SERVE_ARGS=${SERVE_ARGS:-}
METRICS_PORT=${METRICS_PORT:-}
START_TIMEOUT=${START_TIMEOUT:-30}
PATH=$PATH:/usr/sbin:/sbin
REDIS_SERVER=${REDIS_SERVER:-$(command -v redis-server || true)}
NGINX=${NGINX:-$(command -v nginx || true)}

t0=$(date +%s.%N)
elapsed() { awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
log() { echo "start.sh [$(elapsed) s]: $*" >&2; }
logs_of() {
  echo "$RUN_DIR/logs/$1.log"
  [[ $1 != nginx ]] || echo "$RUN_DIR/nginx/error.log"
}
die() {
  log "FAILED: $*"
  # Every process that has exited by now, not only the one being waited for (a busy port range
  # fails several).
  local name f
  for name in "${started[@]}"; do
    if ! alive "${pid_of[$name]}"; then
      log "$name (pid ${pid_of[$name]}) has exited"
      while read -r f; do
        [[ " ${show_logs[*]} " == *" $f "* ]] || show_logs+=("$f")
      done < <(logs_of "$name")
    fi
  done
  for f in "${show_logs[@]}"; do [[ -s $f ]] && { echo "--- $f (last 20 lines)" >&2; tail -n 20 "$f" >&2; }; done
  RUN_DIR=$RUN_DIR "$here/stop.sh" >&2 || true
  exit 1
}
show_logs=()
started=()          # the processes started so far, by name (redis, splinegrid-I, nginx)
declare -A pid_of   # their pids

[[ $STORE == redis || $STORE == memory ]] || { echo "start.sh: STORE must be redis or memory" >&2; exit 2; }
[[ -x $SPLINEGRID ]] || { echo "start.sh: no splinegrid binary at $SPLINEGRID (set SPLINEGRID)" >&2; exit 2; }
[[ -n $NGINX && -x $NGINX ]] || { echo "start.sh: nginx not found (apt-get install nginx-light)" >&2; exit 2; }
if [[ $STORE == redis ]]; then
  [[ -n $REDIS_SERVER && -x $REDIS_SERVER ]] || { echo "start.sh: redis-server not found (apt-get install redis-server)" >&2; exit 2; }
  help=$("$SPLINEGRID" help serve 2>&1 || true)
  if ! grep -q -- '--store ' <<<"$help"; then
    echo "start.sh: $SPLINEGRID has no --store flag (too old a build); rebuild it, or STORE=memory to check the plumbing" >&2
    exit 2
  fi
fi
# The RUN_DIR/cmd scripts must work from any directory.
absolute() { if [[ $1 == /* ]]; then echo "$1"; else echo "$PWD/$1"; fi; }
SPLINEGRID=$(absolute "$SPLINEGRID") NGINX=$(absolute "$NGINX")
[[ $STORE == memory ]] || REDIS_SERVER=$(absolute "$REDIS_SERVER")
read -r -a serve_args <<<"$SERVE_ARGS"

# ---------------------------------------------------------------- ports
for v in NGINX_PORT REPLICA_PORT REDIS_PORT ${METRICS_PORT:+METRICS_PORT}; do
  if ! [[ ${!v} =~ ^[1-9][0-9]*$ ]] || ((${!v} > 65535)); then
    echo "start.sh: $v=${!v} is not a port number" >&2; exit 2
  fi
done
[[ $REPLICAS =~ ^[1-9][0-9]*$ ]] || { echo "start.sh: REPLICAS=$REPLICAS is not a positive number" >&2; exit 2; }
((REPLICA_PORT + REPLICAS - 1 <= 65535)) || { echo "start.sh: REPLICA_PORT + REPLICAS - 1 > 65535" >&2; exit 2; }
# Every process this script starts, in start order, with its port and the setting that chose it.
names=() ports=() vars=()
if [[ $STORE == redis ]]; then names+=(redis); ports+=("$REDIS_PORT"); vars+=(REDIS_PORT); fi
for ((i = 0; i < REPLICAS; i++)); do
  names+=("splinegrid-$i"); ports+=($((REPLICA_PORT + i))); vars+=("REPLICA_PORT+$i")
done
names+=(nginx); ports+=("$NGINX_PORT"); vars+=(NGINX_PORT)
# Metrics listeners: checked for clashes and for being free like the others (not for readiness).
metric_ports=()
if [[ -n $METRICS_PORT ]]; then
  ((METRICS_PORT + REPLICAS - 1 <= 65535)) || { echo "start.sh: METRICS_PORT + REPLICAS - 1 > 65535" >&2; exit 2; }
  for ((i = 0; i < REPLICAS; i++)); do
    metric_ports+=($((METRICS_PORT + i)))
    for ((d = 0; d < ${#names[@]}; d++)); do
      [[ $((METRICS_PORT + i)) != "${ports[$d]}" ]] ||
          { echo "start.sh: ${vars[$d]} and METRICS_PORT+$i are both port $((METRICS_PORT + i))" >&2; exit 2; }
    done
  done
fi
for ((c = 0; c < ${#names[@]}; c++)); do
  for ((d = 0; d < c; d++)); do
    [[ ${ports[$c]} != "${ports[$d]}" ]] ||
        { echo "start.sh: ${vars[$d]} and ${vars[$c]} are both port ${ports[$c]}" >&2; exit 2; }
  done
done

# Refuse to start over a topology that is still running from this RUN_DIR.
for pidfile in "$RUN_DIR"/*.pid; do
  [[ -e $pidfile ]] || continue
  pid=$(<"$pidfile")
  if [[ -n $pid ]] && kill -0 "$pid" 2>/dev/null; then
    echo "start.sh: $pidfile: process $pid is running; run deploy/local/stop.sh first (RUN_DIR=$RUN_DIR)" >&2
    exit 1
  fi
  rm -f "$pidfile"
done
# Refuse ports that something else listens on: otherwise the readiness checks below could be
# answered by that listener while the process started here fails to bind and exits.
busy=0
for ((c = 0; c < ${#names[@]}; c++)); do
  port=${ports[$c]}
  port_listening "$port" || continue
  case ${vars[$c]} in
    REPLICA_PORT*) hint="set REPLICA_PORT so that REPLICA_PORT..REPLICA_PORT+$((REPLICAS - 1)) are free" ;;
    *) hint="set ${vars[$c]} to a free port" ;;
  esac
  echo "start.sh: port $port (${vars[$c]}, for ${names[$c]}) is in use on 127.0.0.1 by $(port_users "$port"); $hint, or stop that process" >&2
  busy=1
done
for port in "${metric_ports[@]}"; do
  port_listening "$port" || continue
  echo "start.sh: port $port (metrics) is in use on 127.0.0.1 by $(port_users "$port"); set METRICS_PORT so that METRICS_PORT..METRICS_PORT+$((REPLICAS - 1)) are free, or stop that process" >&2
  busy=1
done
((busy == 0)) || { echo "start.sh: nothing started" >&2; exit 1; }

mkdir -p "$RUN_DIR"
RUN_DIR=$(cd "$RUN_DIR" && pwd)
mkdir -p "$RUN_DIR/logs" "$RUN_DIR/nginx" "$RUN_DIR/cmd"
rm -f "$RUN_DIR/address"
for ((c = 0; c < ${#names[@]}; c++)); do
  echo "${names[$c]} ${ports[$c]}"
  : >"$RUN_DIR/logs/${names[$c]}.log"
done >"$RUN_DIR/ports"

# Writes RUN_DIR/cmd/NAME.sh, which starts process NAME (listening on PORT) in the background
# with the command line given, appending to RUN_DIR/logs/NAME.log and writing RUN_DIR/NAME.pid
# (what stop.sh stops); then runs it. Usage: start_process NAME PORT COMMAND...
start_process() {
  local name=$1 port=$2; shift 2
  local file=$RUN_DIR/cmd/$name.sh
  # shellcheck disable=SC2016  # the $ expressions are for the written script
  {
    echo '#!/usr/bin/env bash'
    echo "# Written by deploy/local/start.sh: starts $name in the background exactly as start.sh"
    echo "# did. Rerun it to restart $name by hand; it writes the pid file, so stop.sh stops it."
    echo 'set -euo pipefail'
    printf 'port=%q pidfile=%q log=%q program=%q\n' "$port" "$RUN_DIR/$name.pid" \
        "$RUN_DIR/logs/$name.log" "$(basename "$1")"
    cat <<'EOS'
pid=$(cat "$pidfile" 2>/dev/null || true)
if [[ $pid =~ ^[0-9]+$ ]] && tr '\0' ' ' 2>/dev/null <"/proc/$pid/cmdline" | grep -q -- "$program"; then
  echo "$0: $program is running already (pid $pid in $pidfile); not started" >&2
  exit 1
fi
if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
  echo "$0: port $port is in use already; not started" >&2
  if command -v ss >/dev/null; then ss -ltnp "sport = :$port" >&2; fi
  exit 1
fi
EOS
    printf 'nohup'
    printf ' %q' "$@"
    printf ' </dev/null >>"$log" 2>&1 &\n'
    echo 'echo $! >"$pidfile"'
    echo 'echo "$0: started pid $! on 127.0.0.1:$port (log $log)"'
  } >"$file"
  chmod +x "$file"
  "$file" >/dev/null || die "$file could not start $name"
  pid_of[$name]=$(<"$RUN_DIR/$name.pid")
  started+=("$name")
}

# True when process $1 is what listens on port $2, or `ss -ltnp` cannot tell.
owns_port() {
  local listeners
  listeners=$(port_pids "$2")
  [[ -z $listeners ]] || grep -qx -- "$1" <<<"$listeners"
}

# Waits until "$@" succeeds while process NAME is alive and listens on PORT; fails when NAME
# exits or START_TIMEOUT passes. Usage: wait_until NAME PORT PROBE...
wait_until() {
  local name=$1 port=$2; shift 2
  local pid=${pid_of[$name]} deadline=$(( $(date +%s) + START_TIMEOUT )) other="" f
  show_logs=()
  while read -r f; do show_logs+=("$f"); done < <(logs_of "$name")
  while :; do
    alive "$pid" || die "$name (pid $pid) exited during start-up$other"
    if "$@" >/dev/null 2>&1; then
      # The answer counts only if it came from the process started here.
      alive "$pid" || die "$name (pid $pid) exited during start-up; port $port answered anyway, from $(port_users "$port")"
      owns_port "$pid" "$port" && return 0
      other="; port $port is held by $(port_users "$port"), not by $name (pid $pid)"
    fi
    (( $(date +%s) < deadline )) || die "$name not ready after ${START_TIMEOUT}s$other"
    sleep 0.2
  done
}

# ---------------------------------------------------------------- redis
store_flag=()
if [[ $STORE == redis ]]; then
  mkdir -p "$RUN_DIR/redis"
  # Durability: every write is in the AOF and fsync'ed before Redis replies, so a revision the
  # server acknowledged survives a crash or power loss of this machine (see deploy/README.md).
  cat > "$RUN_DIR/redis.conf" <<EOF2
bind 127.0.0.1 -::1
port $REDIS_PORT
protected-mode yes
daemonize no
dir $RUN_DIR/redis
logfile ""
appendonly yes
appendfsync always
appendfilename "appendonly.aof"
appenddirname "appendonlydir"
save ""
EOF2
  log "redis-server on 127.0.0.1:$REDIS_PORT (AOF, appendfsync always, data in $RUN_DIR/redis)"
  start_process redis "$REDIS_PORT" "$REDIS_SERVER" "$RUN_DIR/redis.conf"
  redis_ping() { [[ $(redis-cli -h 127.0.0.1 -p "$REDIS_PORT" ping 2>/dev/null) == PONG ]]; }
  if command -v redis-cli >/dev/null; then
    wait_until redis "$REDIS_PORT" redis_ping
  else
    wait_until redis "$REDIS_PORT" port_listening "$REDIS_PORT"
  fi
  store_flag=("--store=redis://127.0.0.1:$REDIS_PORT")
fi

# ---------------------------------------------------------------- replicas
upstreams=()
for ((i = 0; i < REPLICAS; i++)); do
  port=$((REPLICA_PORT + i))
  upstreams+=(--upstream "127.0.0.1:$port")
  metrics_flag=()
  [[ -z $METRICS_PORT ]] || metrics_flag=(--metrics_address="127.0.0.1:$((METRICS_PORT + i))")
  # nginx runs on loopback and names each client's connection (x-client-address): without
  # tokens that is the caller, for fair turns and per-caller limits.
  start_process "splinegrid-$i" "$port" "$SPLINEGRID" serve --address="127.0.0.1:$port" \
      --trusted_proxies=127.0.0.1 "${store_flag[@]}" "${metrics_flag[@]}" --shutdown_grace="$SHUTDOWN_GRACE" "${serve_args[@]}"
done
log "$REPLICAS splinegrid replicas on 127.0.0.1:$REPLICA_PORT..$((REPLICA_PORT + REPLICAS - 1)) (store: ${store_flag[*]:-memory})"
for ((i = 0; i < REPLICAS; i++)); do
  port=$((REPLICA_PORT + i))
  wait_until "splinegrid-$i" "$port" "$SPLINEGRID" health --server="127.0.0.1:$port" --timeout=2s
done
log "every replica answers SERVING"

# ---------------------------------------------------------------- nginx
"$here/../nginx/render.sh" --run-dir "$RUN_DIR/nginx" --listen "127.0.0.1:$NGINX_PORT" \
    "${upstreams[@]}" > "$RUN_DIR/nginx/nginx.conf"
show_logs=("$RUN_DIR/logs/nginx.log" "$RUN_DIR/nginx/error.log")
"$NGINX" -p "$RUN_DIR/nginx" -c "$RUN_DIR/nginx/nginx.conf" -t >"$RUN_DIR/logs/nginx.log" 2>&1 \
    || die "nginx -t rejected $RUN_DIR/nginx/nginx.conf"
start_process nginx "$NGINX_PORT" "$NGINX" -p "$RUN_DIR/nginx" -c "$RUN_DIR/nginx/nginx.conf" \
    -g 'daemon off;'
wait_until nginx "$NGINX_PORT" "$SPLINEGRID" health --server="127.0.0.1:$NGINX_PORT" --timeout=2s
log "nginx on 127.0.0.1:$NGINX_PORT routes to the replicas (hash on x-splinegrid-grid)"

# Everything answered; is every process started here still running, on its own port?
for ((c = 0; c < ${#names[@]}; c++)); do
  name=${names[$c]} port=${ports[$c]}
  show_logs=()
  while read -r f; do show_logs+=("$f"); done < <(logs_of "$name")
  alive "${pid_of[$name]}" || die "$name (pid ${pid_of[$name]}) has exited"
  owns_port "${pid_of[$name]}" "$port" ||
      die "port $port is held by $(port_users "$port"), not by $name (pid ${pid_of[$name]})"
done

echo "127.0.0.1:$NGINX_PORT" > "$RUN_DIR/address"
cat <<EOF2
splinegrid topology ready in $(elapsed) s (RUN_DIR=$RUN_DIR, logs in $RUN_DIR/logs)
  clients:  $SPLINEGRID --server=127.0.0.1:$NGINX_PORT list
  restart:  $RUN_DIR/cmd/NAME.sh (NAME: ${names[*]}; after it died or was stopped)
  stop:     RUN_DIR=$RUN_DIR $here/stop.sh
SPLINEGRID_SERVER=127.0.0.1:$NGINX_PORT
EOF2
