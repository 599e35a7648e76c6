#!/bin/bash
# Run a pvpython script offscreen: `scripts/pvrun.sh SCRIPT ARGS...` = `xvfb-run -a pvpython SCRIPT ARGS...`
# with Mesa's software renderer, retried when ParaView's X start-up itself crashes.
#
# Why: on this kind of machine (no GPU, Xvfb), ParaView 5.11's pvpython intermittently aborts while
# it opens its render window ("vtkXOpenGLRenderWindow: bad X server connection", SIGABRT, exit
# status 134) before the script's checks run, also with --no-mpi and HWLOC_COMPONENTS=-gl (so not
# the MPI launcher's probe of X displays); measured here on 4 December 2026, 2 cores at a load of
# 12-17: every start with the hardware GL path of Mesa (3 of 3), 1 to 4 starts in 6 with
# LIBGL_ALWAYS_SOFTWARE=1, and 4 in a row once while a cargo test ran; never after the window is
# open. Up to 6 attempts.
# A retry is only for that crash (status 134 with that message): any other failure, a check that
# fails included, is returned at once.
set -u
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for attempt in 1 2 3 4 5 6; do
  LIBGL_ALWAYS_SOFTWARE=1 xvfb-run -a pvpython "$@" > "$log" 2>&1
  rc=$?
  if [ $rc -eq 134 ] && grep -q "bad X server connection" "$log"; then
    echo "pvrun: ParaView's X start-up crashed (attempt $attempt, status 134, bad X server connection): retrying" >&2
    continue
  fi
  # the script's own lines (not ParaView's stack traces)
  grep -v -E '^\s*[0-9]+\s+0x|^\s*$' "$log"
  exit $rc
done
echo "pvrun: ParaView's X start-up crashed 6 times: $*" >&2
grep -v -E '^\s*[0-9]+\s+0x' "$log" | tail -5 >&2
exit 134
