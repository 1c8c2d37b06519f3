#!/bin/bash
# The README's MUKCa table: for each shipped arm (examples/mukca), lrcal's socket calibration on
# one placement of the two-socket block, judged on every other placement against the nominal
# model: the RMS spread of the predicted ball centre about its mean in each socket, and the error
# of the predicted 50 mm socket distance (mm). Prints a Markdown table.
#
# usage: scripts/mukca_table.sh [LRCAL]      (default: build/lrcal)
set -euo pipefail
lrcal=${1:-build/lrcal}
data=examples/mukca
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
figures() {  # robot file (plus options), socket data → "spread | distance error"
  "$lrcal" accuracy "$@" --socket-distance 0,1=0.05 --format json |
    python3 -c 'import json, sys
j = json.load(sys.stdin)
print("%.3f | %+.3f" % (j["rms_spread"] * 1e3, j["distances"][0]["error"] * 1e3))'
}
echo "| arm | calibrated on | judged on | nominal spread [mm] | nominal distance error [mm] | lrcal spread [mm] | lrcal distance error [mm] |"
echo "|---|---|---|---:|---:|---:|---:|"
for pair in panda_1:front panda_2_clean:front_center panda_3:frontcenter panda_4_clean:front \
            panda_6:front panda_7:front; do
  arm=${pair%%:*} training=${pair#*:}
  "$lrcal" identify --sensor socket --robot $data/panda.urdf --tool-link ball_link \
    --data "$data/${arm}_${training}.csv" --socket-distance 0,1=0.05 \
    --fix target_x,target_y,target_z --auto-fix --sigma-mm 0.3 \
    --write-robot "$work/$arm.yaml" > "$work/$arm.txt" 2>&1
  for file in "$data/${arm}"_*.csv; do
    placement=$(basename "$file" .csv)
    placement=${placement#"${arm}"_}
    [ "$placement" = "$training" ] && continue
    nominal=$(figures --robot $data/panda.urdf --tool-link ball_link --sockets "$file")
    calibrated=$(figures --robot "$work/$arm.yaml" --sockets "$file")
    echo "| $arm | $training | $placement | $nominal | $calibrated |"
  done
done
