#!/bin/bash
# Runs a long training in the background across sessions (the dataset
# table's, docs/results.md), on top of scripts/carry_run.sh:
#
#   scripts/background_train.sh start NAME   restore runs/NAME if it is not
#       there, then resume it niced on one core; output in runs/NAME.log
#   scripts/background_train.sh status NAME  its last progress line
#   scripts/background_train.sh stop NAME    SIGINT (the trainer saves its
#       checkpoint), wait for it, then carry it (commit assets/runs/NAME)
#
# The training runs a copy of build/mimic2d and of the run's config, so that
# rebuilding the project or the trainer rewriting runs/NAME/config.yaml does
# not touch the running process. The bundles the config names must exist
# (e.g. scripts/make_dataset.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { echo "usage: $0 start|status|stop NAME" >&2; exit 2; }
[ $# -eq 2 ] || usage
action=$1 name=$2
run=runs/$name
pid_file=runs/.$name.pid log=runs/$name.log

running() { [ -f "$pid_file" ] && kill -0 "$(cat "$pid_file")" 2>/dev/null; }

case $action in
  start)
    if running; then
      echo "background_train: $name is already running (pid $(cat "$pid_file"))" >&2
      exit 1
    fi
    [ -f "$run/checkpoint.pt" ] || scripts/carry_run.sh restore "$name"
    [ -x build/mimic2d ] || { echo "background_train: build/mimic2d not built (./setup.sh --no-demo)" >&2; exit 1; }
    cp build/mimic2d "runs/.$name.bin"
    cp "$run/config.yaml" "runs/.$name.yaml"
    OMP_NUM_THREADS=1 nohup nice -n 5 "runs/.$name.bin" train "runs/.$name.yaml" \
      --resume >> "$log" 2>&1 &
    echo $! > "$pid_file"
    echo "background_train: $name started (pid $!), output in $log"
    ;;
  status)
    state=stopped
    running && state="running (pid $(cat "$pid_file"))"
    echo "background_train: $name $state"
    [ -f "$log" ] && tail -n 1 "$log"
    ;;
  stop)
    if ! running; then
      echo "background_train: $name is not running" >&2
      exit 1
    fi
    pid=$(cat "$pid_file")
    kill -INT "$pid"
    # The trainer finishes its iteration and writes the checkpoint.
    for _ in $(seq 300); do kill -0 "$pid" 2>/dev/null || break; sleep 1; done
    if kill -0 "$pid" 2>/dev/null; then
      echo "background_train: $name did not stop within 300 s" >&2
      exit 1
    fi
    rm -f "$pid_file"
    tail -n 1 "$log"
    scripts/carry_run.sh save "$name"
    ;;
  *) usage ;;
esac
