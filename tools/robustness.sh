#!/usr/bin/env bash
# moved to tools/scripts/robustness.sh; this stub keeps the old spelling working
exec bash "$(dirname "$0")/scripts/robustness.sh" "$@"
