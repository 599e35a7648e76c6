#!/bin/bash
# Run a pvpython script offscreen: `scripts/pvrun.sh SCRIPT ARGS...` = `xvfb-run -a pvpython SCRIPT ARGS...`
# with Mesa's software renderer, retried when ParaView's X start-up itself crashes.
#
# Why: on this kind of machine (no GPU, Xvfb), ParaView 5.11's pvpython intermittently aborts while
# it opens its render window ("vtkXOpenGLRenderWindow: bad X server connection", SIGABRT, exit
# status 134) before the script's checks run; measured here: 1 in 2 to 2 in 3 starts with the
# hardware GL path, about 1 in 3 with LIBGL_ALWAYS_SOFTWARE=1, never after the window is open.
# A retry is only for that crash (status 134 with that message): any other failure, a check that
# fails included, is returned at once.
set -u
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for attempt in 1 2 3 4; do
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
echo "pvrun: ParaView's X start-up crashed 4 times: $*" >&2
grep -v -E '^\s*[0-9]+\s+0x' "$log" | tail -5 >&2
exit 134
