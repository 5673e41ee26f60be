#!/usr/bin/env bash
# shellcheck disable=SC2086  # $PODMAN_GLOBAL and $PODMAN_RUN are flag lists, split on purpose
# Builds the splinegrid image with podman, runs it, drives it with the host's CLI, stops it, and
# (if the image's binary has --store) restarts it on the same volume to check the grid survived.
# Prints the time of every stage. Exit 0 iff every stage passed.
#
#   docker/smoke.sh                 # from anywhere; needs root podman (see container-base.sh)
#
# Environment:
#   BUILD=0        skip the build and use IMAGE as it is (default 1: build it)
#   IMAGE          image name (default localhost/splinegrid:latest)
#   CONTEXT        build context (default: this repository's root; the image is built from the
#                  files on disk, filtered by docker/Dockerfile.dockerignore)
#   CLI            the host's splinegrid binary that drives the container (default build/splinegrid)
#   PORT           loopback port of the server (default: a free one)
#   KEEP=1         keep the containers and the volume afterwards
#   BINARY         a host splinegrid binary to bind-mount over the image's /usr/local/bin/splinegrid
#                  (tests a newer build in the image's run-time environment without rebuilding;
#                  it must run on this CPU and with the image's libraries)
#   PODMAN_GLOBAL, PODMAN_RUN   podman flags; default: what shared/tools/container-base.sh prints
#                  for this kind of machine (runc, cgroupfs, host network, capped rlimits)
# (Without systemd, podman logs "unable to get systemd connection" for the health check timer;
# that is harmless, `podman healthcheck run` works, and those messages go to files in $work.)
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/.." && pwd)
BUILD=${BUILD:-1}
IMAGE=${IMAGE:-localhost/splinegrid:latest}
CONTEXT=${CONTEXT:-$repo}
CLI=${CLI:-$repo/build/splinegrid}
KEEP=${KEEP:-0}
PODMAN_GLOBAL=${PODMAN_GLOBAL:---runtime runc --cgroup-manager=cgroupfs}
PODMAN_RUN=${PODMAN_RUN:---network host --ulimit nofile=1024:1024 --ulimit nproc=1024:1024}
GRID=$repo/../shared/data/grids/n0012_225-65.p2dfmt
if [[ -z ${PORT:-} ]]; then
  PORT=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
fi
SERVER=127.0.0.1:$PORT
mount_binary=()
[[ -n ${BINARY:-} ]] && mount_binary=(-v "$(realpath "$BINARY"):/usr/local/bin/splinegrid:ro")
name=splinegrid-smoke-$$
volume=splinegrid-smoke-$$
work=$(mktemp -d /tmp/splinegrid-smoke.XXXXXX)
podman() { command podman $PODMAN_GLOBAL "$@"; }

t_all=$(date +%s.%N)
t_stage=$t_all
stage_name=""
results=()
since() { awk -v a="$1" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
stage() { stage_name=$1; t_stage=$(date +%s.%N); echo "=== $stage_name"; }
pass() { results+=("$(printf '%-50s %7s s  ok' "$stage_name" "$(since "$t_stage")")"); }
summary() {
  echo; echo "=== summary (port $PORT, image $IMAGE${BINARY:+, binary $BINARY mounted in the image})"
  printf '%s\n' "${results[@]}"
  printf '%-50s %7s s\n' "total" "$(since "$t_all")"
}
fail() {
  results+=("$(printf '%-50s %7s s  FAILED: %s' "$stage_name" "$(since "$t_stage")" "$*")")
  for c in "$name" "$name-2"; do
    podman container exists "$c" 2>/dev/null && { echo "--- logs of $c"; podman logs --tail 30 "$c" 2>&1; }
  done
  summary
  exit 1
}
cleanup() {
  if [[ $KEEP != 1 ]]; then
    podman rm -f -t 0 "$name" "$name-2" >/dev/null 2>&1
    podman volume rm -f "$volume" >/dev/null 2>&1
    rm -rf "$work"
  else
    echo "kept: containers $name $name-2, volume $volume, files $work"
  fi
}
trap cleanup EXIT

# Waits until the server at $SERVER answers SERVING (host CLI), at most 30 s.
wait_serving() {
  local container=$1 deadline=$(( $(date +%s) + 30 ))
  until "$CLI" health --server="$SERVER" --timeout=2s >/dev/null 2>&1; do
    [[ $(podman inspect --format '{{.State.Running}}' "$container" 2>/dev/null) == true ]] \
        || fail "container $container exited"
    (( $(date +%s) < deadline )) || fail "not SERVING after 30 s"
    sleep 0.2
  done
}

[[ -x $CLI ]] || { echo "smoke.sh: no host CLI at $CLI (set CLI)" >&2; exit 2; }
[[ -f $GRID ]] || { echo "smoke.sh: no $GRID" >&2; exit 2; }

if [[ $BUILD == 1 ]]; then
  stage "build image (podman build)"
  # --format docker keeps HEALTHCHECK (the OCI format has no field for it); --ignorefile
  # because podman 4.3 does not pick up docker/Dockerfile.dockerignore by itself.
  (cd "$CONTEXT" && nice -n 19 podman build --pull=never --format docker $PODMAN_RUN \
      --ignorefile docker/Dockerfile.dockerignore -f docker/Dockerfile -t "$IMAGE" .) \
      > "$work/build.log" 2>&1 || { tail -n 30 "$work/build.log"; fail "podman build (log above)"; }
  pass
fi

stage "image has --store"
# `help serve` lists serve's flags (binaries from before the command table knew only --helpfull).
help=$(podman run --rm --no-healthcheck $PODMAN_RUN "${mount_binary[@]}" "$IMAGE" help serve 2>&1 ||
       podman run --rm --no-healthcheck $PODMAN_RUN "${mount_binary[@]}" "$IMAGE" --helpfull 2>&1)
if grep -q -- '--store ' <<<"$help"; then
  has_store=1
  store_flag=(--store=dir:/var/lib/splinegrid)
  echo "yes: serving with --store=dir:/var/lib/splinegrid on volume $volume"
else
  has_store=0
  store_flag=()
  echo "no: this image's binary predates --store; serving from memory (the volume is mounted but" \
       "unused) and the restart-on-the-same-volume stage is skipped"
fi
pass

stage "start container (volume at /var/lib/splinegrid)"
podman volume create "$volume" >/dev/null || fail "volume create"
podman run -d --name "$name" $PODMAN_RUN "${mount_binary[@]}" -v "$volume:/var/lib/splinegrid" \
    --health-cmd "splinegrid health --server=127.0.0.1:$PORT --timeout=2s" \
    "$IMAGE" serve --address="127.0.0.1:$PORT" --shutdown_grace=8s "${store_flag[@]}" \
    >/dev/null 2>"$work/run.err" || { cat "$work/run.err"; fail "podman run"; }
wait_serving "$name"
owner=$(podman run --rm --no-healthcheck $PODMAN_RUN -v "$volume:/var/lib/splinegrid" --entrypoint stat "$IMAGE" \
    -c '%u:%g %a' /var/lib/splinegrid)
echo "volume root as seen in the container: $owner (uid:gid mode)"
[[ $owner == 10001:10001* ]] || fail "volume not owned by 10001: $owner"
pass

stage "health check inside the container"
podman healthcheck run "$name" || fail "podman healthcheck run: unhealthy"
podman exec "$name" id | grep -q 'uid=10001' || fail "not running as uid 10001"
pass

# Tolerances by boundary kind: one tolerance of 1e-3 everywhere folds this C-grid's thin wall
# cells, and a fit that folds is refused.
stage "fit naca --kinds (host CLI)"
"$CLI" fit "$GRID" --name naca --kinds --server="$SERVER" > "$work/fit.txt" 2>&1 \
    || { cat "$work/fit.txt"; fail "fit"; }
head -n 3 "$work/fit.txt"
pass

stage "list, eval --level 2 -o naca.vts, health"
"$CLI" list --server="$SERVER" | tee "$work/list.txt" | grep -q naca || fail "list has no naca"
"$CLI" eval naca --level 2 -o "$work/naca.vts" --server="$SERVER" >/dev/null || fail "eval"
[[ $(head -c 200 "$work/naca.vts" 2>/dev/null) == *VTKFile* ]] || fail "naca.vts is not VTK"
echo "naca.vts: $(stat -c %s "$work/naca.vts") bytes"
"$CLI" health --server="$SERVER" --timeout=2s || fail "health"
pass

stage "podman stop (SIGTERM; exit code 0 expected)"
podman stop -t 12 "$name" >/dev/null 2>"$work/stop.err" || { cat "$work/stop.err"; fail "podman stop"; }
code=$(podman inspect --format '{{.State.ExitCode}}' "$name")
echo "exit code $code"
[[ $code == 0 ]] || fail "exit code $code after SIGTERM"
pass

if ((has_store)); then
  stage "new container, same volume: get naca"
  podman run -d --name "$name-2" $PODMAN_RUN "${mount_binary[@]}" -v "$volume:/var/lib/splinegrid" \
      "$IMAGE" serve --address="127.0.0.1:$PORT" --shutdown_grace=8s "${store_flag[@]}" \
      >/dev/null 2>"$work/run2.err" || { cat "$work/run2.err"; fail "podman run"; }
  wait_serving "$name-2"
  "$CLI" get naca --server="$SERVER" || fail "naca is gone after the restart"
  "$CLI" eval naca --level 2 -o "$work/naca-2.vts" --server="$SERVER" >/dev/null || fail "eval after restart"
  cmp -s "$work/naca.vts" "$work/naca-2.vts" && echo "eval after restart: identical file" \
      || echo "eval after restart: differs from before (not fatal; compare $work/naca*.vts)"
  podman stop -t 12 "$name-2" >/dev/null 2>"$work/stop2.err" || { cat "$work/stop2.err"; fail "podman stop"; }
  code=$(podman inspect --format '{{.State.ExitCode}}' "$name-2")
  [[ $code == 0 ]] || fail "exit code $code after SIGTERM"
  pass
else
  results+=("$(printf '%-50s %7s    skipped: image has no --store' "restart on the same volume" "-")")
fi

summary
