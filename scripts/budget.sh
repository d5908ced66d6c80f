#!/usr/bin/env bash
# Runs a check within a time budget, and fails when it does not finish in it:
#   scripts/budget.sh BUDGET NAME COMMAND [ARGS...]     (BUDGET as timeout(1) reads it: 45m, 90s)
# Exit status: the command's own when it finishes; 1 with one line on stderr when it is
# stopped at the budget. A check stopped part-way has not checked what it did not reach, so
# running out of time is a failure, never a pass (.ci/run; docs/robustness.md, "Sanitizers").
set -uo pipefail
if [[ $# -lt 3 ]]; then
  echo "usage: scripts/budget.sh BUDGET NAME COMMAND [ARGS...]" >&2
  exit 2
fi
budget=$1 name=$2
shift 2
# timeout signals the command's whole process group (ninja, ctest and the tests they start);
# --kill-after: whatever ignores SIGTERM is killed a minute later.
timeout --kill-after=60 "$budget" "$@"
status=$?
# 124: stopped by SIGTERM at the budget; 137: killed after ignoring it.
if [[ $status -eq 124 || $status -eq 137 ]]; then
  echo "budget.sh: $name did not finish within its $budget budget: FAILED (what it did not reach was not checked)" >&2
  exit 1
fi
exit "$status"
