# Every subcommand answers -h and 'amgsplat help CMD' with its usage; unknown commands fail with 2.
source "$(dirname "$0")/common.sh"
cmds=$("$AMGSPLAT" help | awk '/^commands:/{f=1;next} f&&/^ /{print $1} f&&/^$/{exit}')
[[ -n "$cmds" ]] || fail "no commands listed"
for c in $cmds; do
  "$AMGSPLAT" "$c" -h >"$T/h" || fail "$c -h exited non-zero"
  grep -q "usage: amgsplat $c" "$T/h" || fail "$c -h prints no usage line"
  "$AMGSPLAT" help "$c" | grep "usage: amgsplat $c" >/dev/null || fail "help $c prints no usage"
  ! grep -q "not implemented" "$T/h" || fail "$c is a placeholder"
done
expect_fail 2 "'frobnicate' is not a command" "$AMGSPLAT" frobnicate
expect_fail 2 "unknown option '--nope'" "$AMGSPLAT" info --nope x.ply
"$AMGSPLAT" --version | grep "^amgsplat [0-9]" >/dev/null || fail "--version"
echo "help: $(echo $cmds | wc -w) commands checked"
