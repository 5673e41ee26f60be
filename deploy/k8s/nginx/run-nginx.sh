#!/bin/sh
# Entry point of the nginx balancer pod. Open-source nginx 1.22 resolves the upstream names
# (splinegrid-N.splinegrid-headless) once, at start or reload; a rescheduled replica comes back
# under the same name with a new address. So: start nginx once all names resolve, then check
# the addresses every RESOLVE_INTERVAL seconds and reload nginx (graceful: calls in flight finish
# on the old workers, at most worker_shutdown_timeout) when they changed and the config tests.
set -u
CONF=${CONF:-/etc/nginx/splinegrid/nginx.conf}
RESOLVE_INTERVAL=${RESOLVE_INTERVAL:-10}
hosts=$(sed -n 's/^ *server \([^ :]*\):[0-9]* .*/\1/p' "$CONF")

addresses() {
  for h in $hosts; do
    printf '%s=%s ' "$h" "$(getent hosts "$h" | awk '{print $1}' | sort | tr '\n' ,)"
  done
}
all_resolve() {
  for h in $hosts; do getent hosts "$h" >/dev/null || return 1; done
}

until all_resolve; do echo "run-nginx: waiting for $hosts to resolve"; sleep 2; done
nginx -c "$CONF" -g 'daemon off;' &
pid=$!
stopping=0
# The pod's SIGTERM becomes nginx's graceful stop (SIGQUIT).
trap 'stopping=1; kill -QUIT $pid 2>/dev/null' TERM QUIT INT
last=$(addresses)
while kill -0 "$pid" 2>/dev/null; do
  sleep "$RESOLVE_INTERVAL" &
  wait $!
  [ "$stopping" = 1 ] && break
  now=$(addresses)
  if [ "$now" != "$last" ] && nginx -c "$CONF" -t -q; then
    echo "run-nginx: upstream addresses changed ($now), reloading"
    kill -HUP "$pid" && last=$now
  fi
done
# wait returns early when a signal runs the trap: wait again until nginx has exited.
while :; do
  wait "$pid"
  status=$?
  kill -0 "$pid" 2>/dev/null || exit "$status"
done
