# shellcheck shell=bash
# Helpers of deploy/local/start.sh and stop.sh (sourced by them, not run).

# True when something accepts TCP connections on 127.0.0.1:$1.
port_listening() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }

# The pids of the processes listening on port $1 (any address), one a line, as far as `ss -ltnp`
# shows them: nothing without ss, and nothing for other users' processes unless run as root.
port_pids() {
  command -v ss >/dev/null || return 0
  ss -Hltnp "sport = :$1" </dev/null 2>/dev/null | grep -o 'pid=[0-9]*' | cut -d= -f2 | sort -un
}

# Who listens on port $1, for messages: "pid 123 (/usr/bin/redis-server 127.0.0.1:6379)" (a
# process whose parent also listens there, such as an nginx worker, is left out).
port_users() {
  local pids pid ppid out=()
  if ! command -v ss >/dev/null; then echo "a process ss is not installed to name"; return; fi
  pids=$(port_pids "$1")
  for pid in $pids; do
    ppid=$(sed -n 's/^PPid:[[:space:]]*//p' "/proc/$pid/status" 2>/dev/null)
    grep -qx -- "$ppid" <<<"$pids" && continue
    out+=("pid $pid ($(tr '\0' ' ' 2>/dev/null <"/proc/$pid/cmdline" | cut -c1-200 | sed 's/ *$//'))")
  done
  if ((${#out[@]} == 0)); then
    echo "a process ss -ltnp does not name (another user's? run as root to see it)"
    return
  fi
  local all="" one
  for one in "${out[@]}"; do all+="${all:+, }$one"; done
  echo "$all"
}

# True when process $1 exists and is not a zombie (an exited child nobody has reaped yet).
alive() {
  if ! [[ $1 =~ ^[0-9]+$ ]] || ! kill -0 "$1" 2>/dev/null; then return 1; fi
  [[ $(sed -n 's/^State:[[:space:]]*\([A-Z]\).*/\1/p' "/proc/$1/status" 2>/dev/null) != Z ]]
}
