#!/usr/bin/env bash
# Regenerate docs/images/viewer.png: a 2000x1100 screenshot of the rerun viewer on the
# seeded episode that `make run` records, taken headless (virtual X server, software
# Vulkan rendering). Reruns anywhere; takes ~1-2 min (mostly the episode).
# With `--robot mujoco` the same episode is recorded on the MuJoCo backend instead, into
# docs/images/viewer_mujoco.png (needs the `.[mujoco]` extra and Mesa's EGL).
#
# Debian packages needed (installed automatically when run as root with apt-get):
#   xvfb xauth mesa-vulkan-drivers libvulkan1 xdotool imagemagick
# (Xvfb: virtual X server; mesa-vulkan-drivers: lavapipe, the software Vulkan driver;
#  xdotool: parks the pointer off the window; imagemagick: scales and checks the PNG.)
#
# Usage:  tools/viewer_screenshot.sh [--robot sim|mujoco]
# Env:    VIEWER_SHOT_KEEP_RRD=1  reuse runs/viewer_shot[_mujoco].rrd if present (no new episode)
#         VIEWER_SHOT_VENV=DIR    the virtual environment to use (default .venv)
#         WGPU_BACKEND=vulkan     (default; `gl` fails on llvmpipe: no R32Float render target)
#
# How: the viewer's own `--screenshot-to` mode waits for the recording to load and lay out,
# renders the whole window at 2 px/point (4000x2200 for a 2000x1100-point window), saves it
# and quits; the result is scaled down to 2000x1100. A blueprint file identical to the
# recording's own (scone_bt.viz.blueprint.default_blueprint) but with the time panel in
# "following" mode is loaded next to the recording, so the time cursor sits at the end of
# the episode. The virtual screen is bigger than the window so the pointer can be parked
# outside it (no hover tooltips in the shot).
set -uo pipefail

die() { echo "viewer_screenshot: $*" >&2; exit 1; }

cd "$(dirname "${BASH_SOURCE[0]}")/.." || die "cannot cd to the repo root"

ROBOT=sim
while (($#)); do
    case $1 in
        --robot) [[ $# -ge 2 ]] || die "--robot needs a value: sim or mujoco"; ROBOT=$2; shift 2 ;;
        --robot=*) ROBOT=${1#--robot=}; shift ;;
        *) die "unknown argument '$1'; usage: tools/viewer_screenshot.sh [--robot sim|mujoco]" ;;
    esac
done
case $ROBOT in
    sim) SUFFIX="" ;;
    mujoco) SUFFIX="_mujoco" ;;
    *) die "unknown --robot '$ROBOT'; valid: sim, mujoco" ;;
esac

PKGS=(xvfb xauth mesa-vulkan-drivers libvulkan1 xdotool imagemagick)
missing=()
for p in "${PKGS[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    if [[ $(id -u) == 0 ]] && command -v apt-get >/dev/null; then
        echo "viewer_screenshot: installing ${missing[*]}" >&2
        { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
            --no-install-recommends "${missing[@]}"; } >/dev/null 2>&1 \
            || die "apt-get install ${missing[*]} failed"
    else
        die "missing packages; run: sudo apt-get install -y --no-install-recommends ${missing[*]}"
    fi
fi

VENV=${VIEWER_SHOT_VENV:-.venv}
PY=$VENV/bin/python
[[ -x $PY && -x $VENV/bin/scone-run ]] || die "$VENV/bin/python or $VENV/bin/scone-run missing (run make install)"
if [[ $ROBOT == mujoco ]]; then
    $PY -c 'import mujoco' 2>/dev/null || die "--robot mujoco needs the mujoco package: pip install -e '.[mujoco]'"
fi
# The viewer binary itself, not the .venv/bin/rerun Python wrapper, so `timeout` stops the viewer.
VIEWER=$($PY -c 'import os, rerun_cli; print(os.path.join(os.path.dirname(rerun_cli.__file__), "rerun"))' 2>/dev/null)
[[ -x $VIEWER ]] || die "rerun viewer binary not found (is rerun-sdk installed in .venv?)"

RRD=runs/viewer_shot$SUFFIX.rrd
OUT=docs/images/viewer$SUFFIX.png
W=2000 H=1100
mkdir -p runs docs/images
TMP=$(mktemp -d) || die "mktemp failed"
trap 'rm -rf "$TMP"' EXIT

# 1. Record the seeded episode (the one `make run` records), on the chosen backend.
if [[ ${VIEWER_SHOT_KEEP_RRD:-0} == 1 && -s $RRD ]]; then
    echo "viewer_screenshot: reusing $RRD" >&2
else
    echo "viewer_screenshot: recording $RRD (~30-60 s)" >&2
    $VENV/bin/scone-run --robot "$ROBOT" --headless --seed 0 --save "$RRD" >"$TMP/run.log" 2>&1 \
        || die "scone-run failed: $(tail -n 1 "$TMP/run.log")"
    [[ -s $RRD ]] || die "scone-run wrote no $RRD"
fi

# 2. The recording's blueprint, with the time cursor following the end of the recording.
$PY - "$TMP/end.rbl" >"$TMP/rbl.log" 2>&1 <<'EOF' || die "could not write the blueprint: $(tail -n 1 "$TMP/rbl.log")"
import sys

import rerun.blueprint as rrb

from scone_bt.viz import paths as P
from scone_bt.viz.blueprint import default_blueprint

bp = default_blueprint()
bp.time_panel = rrb.TimePanel(timeline=P.SIM_TIME, state="expanded", play_state="following")
bp.save("scone_bt", sys.argv[1])
EOF

# 3. Open it headless and let the viewer screenshot itself.
echo "viewer_screenshot: rendering the viewer (software Vulkan, ~20-60 s)" >&2
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
# A fresh viewer state every time (XDG_DATA_HOME): the viewer otherwise restores what it persisted in ~/.local/share
# from earlier sessions (yours, or the last screenshot's), so the shot would depend on them.
# Look at the PNG: once, the behaviour-tree panel of one MuJoCo recording came out as unlabelled dots, on every
# render of that file; a new recording of the same episode rendered it laid out.
export XDG_RUNTIME_DIR=$TMP XDG_DATA_HOME=$TMP/data LC_ALL=C.UTF-8
SW=$((2 * W + 100)) SH=$((2 * H + 100))
xvfb-run -a -s "-screen 0 ${SW}x${SH}x24" bash -c '
    xdotool mousemove $(($3 - 10)) $(($4 - 10)) || exit 3
    exec timeout 300 "$0" --window-size "$5" --new --screenshot-to "$1" "$2" "$6"
' "$VIEWER" "$TMP/raw.png" "$RRD" "$SW" "$SH" "${W}x${H}" "$TMP/end.rbl" >"$TMP/viewer.log" 2>&1
rc=$?
[[ -s $TMP/raw.png ]] || die "viewer made no screenshot (rc $rc): $(grep -E 'ERROR|Error|error' "$TMP/viewer.log" | tail -n 1 | cut -c1-300)"

# 4. Scale to 2000x1100 and make sure it is not a blank frame.
convert "$TMP/raw.png" -resize "${W}x${H}!" -strip "$TMP/viewer.png" || die "convert failed"
spread=$(convert "$TMP/viewer.png" -format '%[fx:standard_deviation]' info:) || die "cannot read the screenshot"
awk -v s="$spread" 'BEGIN { exit !(s + 0 > 0.02) }' || die "screenshot is blank (pixel std dev $spread)"
cp "$TMP/viewer.png" "$OUT" || die "cannot write $OUT"
echo "viewer_screenshot: wrote $OUT (${W}x${H})" >&2
