#!/usr/bin/env bash
# Renders deploy/nginx/splinegrid.conf.template into an nginx configuration on stdout.
#
#   deploy/nginx/render.sh --run-dir DIR --listen HOST:PORT --upstream HOST:PORT [--upstream ...]
#       [--tries N] [--workers N] [--fail-timeout 5s] [--stream-timeout 3600s]
#       [--error-log PATH|stderr] [--access-log PATH|off]
#
# --run-dir  absolute directory for pid, lock, logs and temp files (created by nginx / start.sh)
# --listen   address nginx listens on for gRPC (plaintext HTTP/2)
# --upstream a splinegrid replica; repeat once per replica (at least one)
# --tries    calls are tried on at most this many replicas (default: replicas, at most 3)
# Defaults: error log DIR/error.log, access log DIR/access.log, 1 worker.
#
# Then:  nginx -p DIR -c DIR/nginx.conf -g 'daemon off;'   (any user; see the template)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
run_dir="" listen="" tries="" workers=1 fail_timeout=5s stream_timeout=3600s
error_log="" access_log=""
upstreams=()
usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
while (($#)); do
  case "$1" in
    --run-dir) run_dir=$2; shift 2 ;;
    --listen) listen=$2; shift 2 ;;
    --upstream) upstreams+=("$2"); shift 2 ;;
    --tries) tries=$2; shift 2 ;;
    --workers) workers=$2; shift 2 ;;
    --fail-timeout) fail_timeout=$2; shift 2 ;;
    --stream-timeout) stream_timeout=$2; shift 2 ;;
    --error-log) error_log=$2; shift 2 ;;
    --access-log) access_log=$2; shift 2 ;;
    -h|--help) usage ;;
    *) echo "render.sh: unknown argument $1" >&2; usage ;;
  esac
done
[[ -n $run_dir && -n $listen && ${#upstreams[@]} -gt 0 ]] || usage
[[ $run_dir == /* ]] || { echo "render.sh: --run-dir must be absolute" >&2; exit 2; }
if [[ -z $tries ]]; then tries=${#upstreams[@]}; ((tries > 3)) && tries=3; fi
error_log=${error_log:-$run_dir/error.log}
access_log=${access_log:-$run_dir/access.log splinegrid}
[[ $access_log == off ]] || [[ $access_log == *" "* ]] || access_log="$access_log splinegrid"

servers=""
for u in "${upstreams[@]}"; do
  servers+="        server $u max_fails=1 fail_timeout=$fail_timeout;"$'\n'
done
servers=${servers%$'\n'}

# Plain string replacement (no envsubst: nginx's own $variables must stay as they are).
template=$(<"$here/splinegrid.conf.template")
template=${template//@RUN_DIR@/$run_dir}
template=${template//@LISTEN@/$listen}
template=${template//@WORKERS@/$workers}
template=${template//@TRIES@/$tries}
template=${template//@FAIL_TIMEOUT@/$fail_timeout}
template=${template//@STREAM_TIMEOUT@/$stream_timeout}
template=${template//@ERROR_LOG@/$error_log}
template=${template//@ACCESS_LOG@/$access_log}
template=${template//@SERVERS@/$servers}
if [[ $template == *@*@* ]] && grep -qE '@[A-Z_]+@' <<<"$template"; then
  echo "render.sh: unreplaced placeholder: $(grep -oE '@[A-Z_]+@' <<<"$template" | sort -u | tr '\n' ' ')" >&2
  exit 1
fi
printf '%s\n' "$template"
