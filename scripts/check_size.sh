#!/usr/bin/env bash
# Size limits of the sources: apps/ <= 900 lines, files <= 700, functions <= 120 (check_size.py).
#
#   scripts/check_size.sh [ROOT]        # or: scripts/check_size.sh --files FILE...
exec python3 "$(dirname "$0")/check_size.py" "$@"
