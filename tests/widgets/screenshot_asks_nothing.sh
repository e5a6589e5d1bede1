#!/usr/bin/env bash
# `flexarm --screenshot` while another instance's autosave lies beside the settings (as when
# two windows share them): the run asks no recovery question, saves the screenshot, ends
# within the time limit and leaves the other instance's autosave in place.
#   screenshot_asks_nothing.sh FLEXARM SAMPLE_LOG
set -euo pipefail
flexarm="$1"
log="$2"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/config/FlexArm"
autosave="$dir/config/FlexArm/autosave-session.json"
echo '{"note": "autosave of another running window"}' > "$autosave"
if ! XDG_CONFIG_HOME="$dir/config" timeout 120 "$flexarm" --screenshot "$dir/shot.png" "$log"; then
  echo "screenshot run failed or hung" >&2
  exit 1
fi
[[ -s "$dir/shot.png" ]] || { echo "no screenshot written" >&2; exit 1; }
head -c 8 "$dir/shot.png" | grep -q PNG || { echo "the screenshot is no PNG" >&2; exit 1; }
[[ -f "$autosave" ]] || { echo "the other instance's autosave was removed" >&2; exit 1; }
echo "screenshot taken, autosave kept"
