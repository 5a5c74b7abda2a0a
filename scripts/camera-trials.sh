#!/usr/bin/env bash
# Tracking without a camera.json (docs/numbers.md, "Estimated cameras"):
# the README's three-activity sequence (hand circles, horizontal and
# vertical waving, 3 repetitions each) performed by the tracker's capsules
# and filmed at 160×120 (or SIZE) by cameras placed 0.8–2.0 m high, 2.5–6 m away,
# with vertical fields of view of 30–70° and tilts of 0–30° (the ones of
# that grid that keep the person in the frame, spread so that every value
# of each is used), tracked with vocab/default.vocab, 25 particles, eq. 10:
#
# - told: the true camera.json;
# - auto, fov told: `--camera auto --fov` with the true field of view;
# - auto: `--camera auto` with nothing told.
#
#   bash scripts/camera-trials.sh [WORK_DIR]        # about 2 minutes on 2 cores
#   SIZE=320x240 bash scripts/camera-trials.sh      # the same at 320×240
#
# Each row is the mean over seeds 1–3.
source "$(dirname "$0")/common.sh" "$@"
seeds="1 2 3"
export SIZE="${SIZE:-160x120}"

rm -rf sequence cameras
"$imitate" -q synth --sequence circles,wave-h,wave-v --reps 3 -o sequence
mkdir cameras
# The cameras: every (height, distance, fov, tilt) of the grid whose view
# holds a person with arms raised and spread, then a spread of them.
python3 - <<'PY'
import itertools, json, math, os
W, H = (int(side) for side in os.environ["SIZE"].split("x"))
def spec(h, d, fov, tilt):
    f = H / 2 / math.tan(math.radians(fov) / 2)
    t = math.radians(tilt)
    return {"width": W, "height": H, "fx": f, "fy": f, "cx": W / 2, "cy": H / 2,
            "position": [0.0, h, d], "look_at": [0.0, h - math.sin(t), d - math.cos(t)], "up": [0.0, 1.0, 0.0]}
def sees(c):
    f = c["fx"]
    h, d = c["position"][1], c["position"][2]
    tilt = math.atan2(h - c["look_at"][1], d - c["look_at"][2])
    for x, y, z in [(0, 0, 0.25), (0, 0, -0.25), (0, 2.2, 0), (0.9, 1.45, 0), (-0.9, 1.45, 0)]:
        dy, dz = y - h, d - z
        depth = dz * math.cos(tilt) - dy * math.sin(tilt)
        down = -dy * math.cos(tilt) - dz * math.sin(tilt)
        u, v = c["cx"] + f * x / depth, c["cy"] + f * down / depth
        if not (3 <= u <= W - 3 and 3 <= v <= H - 3):
            return False
    return True
grid = [(h, d, fov, tilt) for h, d, fov, tilt in itertools.product((0.8, 1.4, 2.0), (2.5, 4.0, 6.0), (30, 50, 70), (0, 15, 30))
        if sees(spec(h, d, fov, tilt))]
# Greedy spread: each next camera the one farthest (in grid steps) from those chosen.
def gap(a, b):
    scale = (0.6, 1.75, 20, 15)
    return sum(((x - y) / s) ** 2 for x, y, s in zip(a, b, scale))
chosen = [min(grid, key=lambda c: (c[0] - 1.4) ** 2 + (c[1] - 4) ** 2 + (c[2] - 50) ** 2 / 100 + (c[3] / 15) ** 2)]
while len(chosen) < 10:
    chosen.append(max(grid, key=lambda c: min(gap(c, o) for o in chosen)))
for h, d, fov, tilt in chosen:
    name = f"h{h}-d{d}-fov{fov}-tilt{tilt}"
    json.dump(spec(h, d, fov, tilt), open(f"cameras/{name}.json", "w"), indent=2)
PY

track() {
  local name=$1
  shift
  for seed in $seeds; do
    "$imitate" -q track frames --vocab "$vocab" -o "runs/$name-$seed" --particles 25 --feedback --seed "$seed" \
      --force "$@"
    "$imitate" -q score "runs/$name-$seed" --truth truth.csv
  done
}

echo "| camera (height m, distance m, fov °, tilt °) | upper body told / auto+fov / auto (mm) | ratio auto+fov / auto | recognition told / auto+fov / auto (%) | camera height found (auto+fov) | tilt found (auto+fov) | decided by |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for camera in cameras/*.json; do
  name=$(basename "$camera" .json)
  rm -rf video
  "$imitate" -q render sequence/sequence.bvh -o video --labels sequence/labels.csv --camera "$camera" --force
  # The folder of frames alone, so no camera.json beside it is found.
  rm -rf frames truth.csv && cp -r video/frames frames && cp video/truth.csv truth.csv
  fov=$(python3 -c "import json, math; c = json.load(open('$camera')); print(2 * math.degrees(math.atan(c['height'] / 2 / c['fy'])))")
  track "$name-told" --camera "$camera"
  track "$name-fov" --camera auto --fov "$fov"
  track "$name-auto" --camera auto
  python3 - "$name" "$seeds" <<'PY'
import json, sys
name, seeds = sys.argv[1], sys.argv[2].split()
def mean(mode, f):
    return sum(f(json.load(open(f"runs/{name}-{mode}-{s}/metrics.json")), json.load(open(f"runs/{name}-{mode}-{s}/summary.json"))) for s in seeds) / len(seeds)
upper = {m: mean(m, lambda x, _: x["upper_body_mm"]) for m in ("told", "fov", "auto")}
rec = {m: mean(m, lambda x, _: 100 * x["recognition_accuracy_settled"]) for m in ("told", "fov", "auto")}
height = mean("fov", lambda _, s: s["camera_estimate"]["camera_height_m"])
tilt = mean("fov", lambda _, s: s["camera_estimate"]["tilt_deg"])
decided = json.load(open(f"runs/{name}-fov-{seeds[0]}/summary.json"))["camera_estimate"]["decided_by"]
h, d, fov, t = (part.lstrip("hdfovtil") for part in name.split("-"))
print(f"| {h}, {d}, {fov}, {t} | {upper['told']:.1f} / {upper['fov']:.1f} / {upper['auto']:.1f} "
      f"| {upper['fov'] / upper['told']:.2f} / {upper['auto'] / upper['told']:.2f} "
      f"| {rec['told']:.0f} / {rec['fov']:.0f} / {rec['auto']:.0f} | {height:.2f} | {tilt:.1f} | {decided} |")
PY
done
