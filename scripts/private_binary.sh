#!/bin/bash
# Sourced, not run: `private_binary` sets $bin to a private copy of
# build/mimic2d, removed when the sourcing script exits. The dataset scripts
# run the binary for minutes; rebuilding the project meanwhile rewrites
# build/mimic2d, and the steps started after that failed with "Permission
# denied" (seen 2026-12-02 while make_dataset.sh ran beside a build).
# A missing build is named, exit 1. It takes the script's EXIT trap: a
# script with its own removes "$bin" there too.

private_binary() {
  if [ ! -x build/mimic2d ]; then
    echo "$(basename "$0"): build/mimic2d not built (./setup.sh --no-demo)" >&2
    exit 1
  fi
  bin=$(mktemp "${TMPDIR:-/tmp}/mimic2d.XXXXXX")
  cp build/mimic2d "$bin"
  chmod u+x "$bin"  # mktemp made it 0600; cp keeps that mode
  trap 'rm -f "$bin"' EXIT
}
