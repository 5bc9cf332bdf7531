#!/usr/bin/env bash
# scripts/run.sh TOOL [ARGS...]: set up and build, then run a tool of the package (as rosrun would).
set -euo pipefail
if [[ $# -lt 1 ]]; then
  echo "usage: scripts/run.sh TOOL [ARGS...]" >&2
  exit 2
fi
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" >&2
exec rosrun laser_dpslam "$@"
