# SIGINT, SIGTERM and SIGHUP during a write (issue #13): the temporary OUT.tmp.<pid> is removed,
# the process still dies of the signal (exit 128+N), and a target that existed is left as it was.
# The write is an ascii PLY of 400000 points (several seconds here, read back before the rename),
# so the signal lands while the temporary exists: the script waits for it to appear.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
"$A" synth sphere -o "$T/in.ply" --points 400000 --quiet

for sig in INT TERM HUP; do
  printf 'the old target\n' >"$T/out.ply"
  # a background job of a script starts with SIGINT ignored; a user's Ctrl-C reaches a foreground one
  env --default-signal=$sig "$A" convert --ascii "$T/in.ply" "$T/out.ply" >/dev/null 2>"$T/err" &
  pid=$!
  for _ in $(seq 1 3000); do
    [[ -e "$T/out.ply.tmp.$pid" ]] && break
    sleep 0.01
  done
  [[ -e "$T/out.ply.tmp.$pid" ]] || fail "SIG$sig: the temporary '$T/out.ply.tmp.$pid' never appeared"
  sleep 0.2 # well inside the write
  kill -s $sig "$pid"
  st=0; wait "$pid" || st=$?
  want=$((128 + $(kill -l $sig)))
  ((st == want)) || fail "SIG$sig: exit $st, expected $want (died of the signal); stderr: $(cat "$T/err")"
  left=$(ls "$T" | grep -c '\.tmp\.' || true)
  ((left == 0)) || fail "SIG$sig: temporaries left: $(ls "$T" | grep '\.tmp\.')"
  [[ "$(cat "$T/out.ply")" == "the old target" ]] || fail "SIG$sig: the target was changed"
  echo "SIG$sig: exit $st, no temporary left, target untouched"
done

# the same write, uninterrupted, replaces the target with a readable file
"$A" convert --ascii "$T/in.ply" "$T/out.ply" >/dev/null
"$A" info "$T/out.ply" | grep -E "^points +400000$" >/dev/null || fail "the finished write is not 400000 points"
