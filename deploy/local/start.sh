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
#   SERVE_ARGS    more serve flags, e.g. "--threads=1 --memory_budget_mb=1024"
#   START_TIMEOUT seconds to wait for each process to become ready (default 30)
#   REDIS_SERVER, NGINX  the binaries (default: redis-server, nginx from PATH, /usr/sbin)
#
# Prints the address to use on the last line: SPLINEGRID_SERVER=127.0.0.1:NGINX_PORT (also in
# RUN_DIR/address). On any failure it stops what it started, prints the failing log and exits 1.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)

RUN_DIR=${RUN_DIR:-/tmp/splinegrid-local}
REPLICAS=${REPLICAS:-3}
NGINX_PORT=${NGINX_PORT:-50051}
REPLICA_PORT=${REPLICA_PORT:-50061}
REDIS_PORT=${REDIS_PORT:-16379}
SPLINEGRID=${SPLINEGRID:-$repo/build/splinegrid}
STORE=${STORE:-redis}
SHUTDOWN_GRACE=${SHUTDOWN_GRACE:-8s}
SERVE_ARGS=${SERVE_ARGS:-}
START_TIMEOUT=${START_TIMEOUT:-30}
PATH=$PATH:/usr/sbin:/sbin
REDIS_SERVER=${REDIS_SERVER:-$(command -v redis-server || true)}
NGINX=${NGINX:-$(command -v nginx || true)}

t0=$(date +%s.%N)
elapsed() { awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
log() { echo "start.sh [$(elapsed) s]: $*" >&2; }
die() {
  log "FAILED: $*"
  # Every replica that has exited by now, not only the one being waited for (a busy port range
  # fails several).
  local r
  for ((r = 0; r < ${#pids[@]}; r++)); do
    if ! kill -0 "${pids[$r]}" 2>/dev/null; then
      log "splinegrid replica $r has exited"
      [[ " ${show_logs[*]} " == *" $RUN_DIR/logs/splinegrid-$r.log "* ]] ||
          show_logs+=("$RUN_DIR/logs/splinegrid-$r.log")
    fi
  done
  for f in "${show_logs[@]}"; do [[ -s $f ]] && { echo "--- $f (last 20 lines)" >&2; tail -n 20 "$f" >&2; }; done
  RUN_DIR=$RUN_DIR "$here/stop.sh" >&2 || true
  exit 1
}
show_logs=()
pids=()

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

mkdir -p "$RUN_DIR"
RUN_DIR=$(cd "$RUN_DIR" && pwd)
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
mkdir -p "$RUN_DIR/logs" "$RUN_DIR/nginx"
rm -f "$RUN_DIR/address"

# Waits until "$@" succeeds, or the process $pid is gone, or START_TIMEOUT passes.
wait_until() {
  local what=$1 pid=$2; shift 2
  local deadline=$(( $(date +%s) + START_TIMEOUT ))
  until "$@" >/dev/null 2>&1; do
    kill -0 "$pid" 2>/dev/null || die "$what exited during start-up"
    (( $(date +%s) < deadline )) || die "$what not ready after ${START_TIMEOUT}s"
    sleep 0.2
  done
}

# ---------------------------------------------------------------- redis
store_flag=()
if [[ $STORE == redis ]]; then
  mkdir -p "$RUN_DIR/redis"
  # Durability: every write is in the AOF and fsync'ed before Redis replies, so a revision the
  # server acknowledged survives a crash or power loss of this machine (see deploy/README.md).
  cat > "$RUN_DIR/redis.conf" <<EOF
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
EOF
  log "redis-server on 127.0.0.1:$REDIS_PORT (AOF, appendfsync always, data in $RUN_DIR/redis)"
  show_logs=("$RUN_DIR/logs/redis.log")
  nohup "$REDIS_SERVER" "$RUN_DIR/redis.conf" </dev/null >"$RUN_DIR/logs/redis.log" 2>&1 &
  echo $! > "$RUN_DIR/redis.pid"
  redis_pid=$!
  redis_ping() { [[ $(redis-cli -h 127.0.0.1 -p "$REDIS_PORT" ping 2>/dev/null) == PONG ]]; }
  if command -v redis-cli >/dev/null; then
    wait_until redis-server "$redis_pid" redis_ping
  else
    wait_until redis-server "$redis_pid" bash -c "exec 3<>/dev/tcp/127.0.0.1/$REDIS_PORT"
  fi
  store_flag=("--store=redis://127.0.0.1:$REDIS_PORT")
fi

# ---------------------------------------------------------------- replicas
upstreams=()
pids=()
for ((i = 0; i < REPLICAS; i++)); do
  port=$((REPLICA_PORT + i))
  upstreams+=(--upstream "127.0.0.1:$port")
  # shellcheck disable=SC2086  # SERVE_ARGS is a list of flags
  nohup "$SPLINEGRID" serve --address="127.0.0.1:$port" "${store_flag[@]}" \
      --shutdown_grace="$SHUTDOWN_GRACE" $SERVE_ARGS \
      </dev/null >"$RUN_DIR/logs/splinegrid-$i.log" 2>&1 &
  pids+=($!)
  echo $! > "$RUN_DIR/splinegrid-$i.pid"
done
log "$REPLICAS splinegrid replicas on 127.0.0.1:$REPLICA_PORT..$((REPLICA_PORT + REPLICAS - 1)) (store: ${store_flag[*]:-memory})"
for ((i = 0; i < REPLICAS; i++)); do
  show_logs=("$RUN_DIR/logs/splinegrid-$i.log")
  wait_until "splinegrid replica $i" "${pids[$i]}" \
      "$SPLINEGRID" health --server="127.0.0.1:$((REPLICA_PORT + i))" --timeout=2s
done
log "every replica answers SERVING"

# ---------------------------------------------------------------- nginx
"$here/../nginx/render.sh" --run-dir "$RUN_DIR/nginx" --listen "127.0.0.1:$NGINX_PORT" \
    "${upstreams[@]}" > "$RUN_DIR/nginx/nginx.conf"
show_logs=("$RUN_DIR/logs/nginx.log" "$RUN_DIR/nginx/error.log")
"$NGINX" -p "$RUN_DIR/nginx" -c "$RUN_DIR/nginx/nginx.conf" -t >"$RUN_DIR/logs/nginx.log" 2>&1 \
    || die "nginx -t rejected $RUN_DIR/nginx/nginx.conf"
nohup "$NGINX" -p "$RUN_DIR/nginx" -c "$RUN_DIR/nginx/nginx.conf" -g 'daemon off;' \
    </dev/null >>"$RUN_DIR/logs/nginx.log" 2>&1 &
nginx_pid=$!
echo $nginx_pid > "$RUN_DIR/nginx.pid"
wait_until nginx "$nginx_pid" "$SPLINEGRID" health --server="127.0.0.1:$NGINX_PORT" --timeout=2s
log "nginx on 127.0.0.1:$NGINX_PORT routes to the replicas (hash on x-splinegrid-grid)"

echo "127.0.0.1:$NGINX_PORT" > "$RUN_DIR/address"
cat <<EOF
splinegrid topology ready in $(elapsed) s (RUN_DIR=$RUN_DIR, logs in $RUN_DIR/logs)
  clients:  $SPLINEGRID --server=127.0.0.1:$NGINX_PORT list
  stop:     RUN_DIR=$RUN_DIR $here/stop.sh
SPLINEGRID_SERVER=127.0.0.1:$NGINX_PORT
EOF
