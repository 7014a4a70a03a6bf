#!/bin/bash
# A host in a few lines of shell, as a PLC program or a script might be: one command at a
# time, its answer read up to CR, a vector tried again while the queue is full. No
# recovery: an answer that does not come within a second ends it (exit 3).
# Usage: shell_host.sh PORT [lower]   ("lower": the bug of writing commands in lower case)
set -u
port="$1"
# 8N1, raw; icrnl: the terminal turns each answer's CR into LF, so that `read` ends there
stty -F "$port" 115200 cs8 -cstopb -parenb raw -echo icrnl || exit 2
exec 3<>"$port"
ask() {
  local body="$1"
  [ "${2:-}" = lower ] && body="${body,,}"
  printf '!0%s\r' "$body" >&3
  IFS= read -r -t 1 answer <&3 || { echo "no answer to $1" >&2; exit 3; }
}
vector() {
  while ask "$1" "${2:-}"; [ "$answer" = 1 ]; do sleep 0.01; done
  [ "$answer" = 0 ] || { echo "$1 refused: $answer" >&2; exit 1; }
}
mode="${2:-}"
ask V5000 "$mode"; [ "$answer" = 0 ] || exit 1
vector L500,0,0 "$mode"
vector L-500,500,0 "$mode"
vector L0,0,0 "$mode"
