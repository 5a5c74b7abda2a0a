#!/usr/bin/env bash
# The humanoid on the ground with real motion capture (issue 20, "Numbers to
# reach"): `imitate execute` of every standing gesture take (wave-*,
# raise-up-*, bow, bye, byebye, guide) and every walk (walk, walk-turn-*) of
# ../shared/mocap/bandai's takes 001 and 002, and of every take of
# ../shared/mocap/real (grouped by its labels.csv: standing, walking, moving
# in place), each as a new user runs it (no flags but the ones
# given here). Prints per group how many stay up, the RMS joint error of
# those that do, how closely the feet followed the take's own contacts
# (summary.json's contact_agreement), and lists the falls; the table is also written to
# WORK_DIR/execute-trials.md.
#
#   bash scripts/execute-trials.sh [WORK_DIR] [-- EXECUTE_FLAGS...]   # under a minute on 2 cores
#
# IMITATE_SHARED is the shared data folder (default: ../shared beside the
# repository).
work_args=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do work_args+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
flags=("$@")
source "$(dirname "$0")/common.sh" "${work_args[@]}"
shared="${IMITATE_SHARED:-$(cd "$repo/.." && pwd)/shared}"
bandai="$shared/mocap/bandai"
real="$shared/mocap/real"
for folder in "$bandai" "$real"; do
  [ -d "$folder" ] || { echo "execute-trials: $folder is missing" >&2; exit 1; }
done

# GROUP TAKE: plays TAKE into runs/GROUP/<name>; a take the command refuses
# is listed with its message.
play() {
  local group=$1 take=$2
  local out="runs/$group/$(basename "$take" .bvh)"
  mkdir -p "runs/$group"
  rm -rf "$out"
  if ! "$imitate" -q execute "$take" -o "$out" "${flags[@]}" 2>"$out.err"; then
    echo "$take: $(tail -1 "$out.err")" >&2
  fi
}

standing='bow|bye|byebye|guide|wave-both-hands|wave-left-hand|wave-right-hand|raise-up-both-hands|raise-up-left-hand|raise-up-right-hand'
walking='walk|walk-turn-left|walk-turn-right'
for take in "$bandai"/*.bvh; do
  name=$(basename "$take" .bvh)
  # dataset-N_{content}_{style}_{id}
  IFS=_ read -r _ content _ id <<<"$name"
  case "$id" in 001|002) ;; *) continue ;; esac
  if [[ "$content" =~ ^($standing)$ ]]; then
    play bandai-standing "$take"
  elif [[ "$content" =~ ^($walking)$ ]]; then
    play bandai-walking "$take"
  fi
done
# real/'s labels.csv names each take's activity: punches, gestures and
# waves are played standing; walks, jumps, kicks and dances move the feet.
while IFS=, read -r file activity _; do
  case "$activity" in
    activity) ;;
    punch|gesture|wave*) play real-standing "$real/$file" ;;
    walk) play real-walking "$real/$file" ;;
    *) play real-moving "$real/$file" ;;
  esac
done <"$real/labels.csv"

python3 - "${flags[*]:-}" <<'PY'
import json, statistics, sys
from pathlib import Path

flags = sys.argv[1]
assisted = "--assist" in flags.split()
lines = [f"`imitate execute {flags}`".replace(" `", "`"), "",
         "| takes | played | stay up | RMS joint error where up (median, max) | feet as the take's (median) | "
         + ("mean assisting force, share of body weight (median, max) | " if assisted else "")
         + "falls (at s) |",
         "| --- | --- | --- | --- | --- | " + ("--- | " if assisted else "") + "--- |"]
for group in sorted(Path("runs").iterdir()):
    if not group.is_dir():
        continue
    played, up, errors, falls, refused, shares, agreement = 0, 0, [], [], [], [], []
    # Every take played leaves its stderr; a refused one no folder.
    for err in sorted(group.glob("*.err")):
        run = err.with_suffix("")
        summary = run / "summary.json"
        if not summary.exists():
            refused.append(run.name)
            continue
        s = json.loads(summary.read_text())
        played += 1
        if s.get("contact_agreement") is not None:
            agreement.append(s["contact_agreement"])
        if s.get("assist"):
            shares.append(s["assist"]["mean_force_share_of_weight"])
        if s["fell"]:
            falls.append(f"{run.name} ({s['fell_at_s']:.1f})")
        else:
            up += 1
            errors.append(s["rms_error_deg"])
    errors.sort()
    where_up = f"{errors[len(errors) // 2]:.1f}°, {errors[-1]:.1f}°" if errors else "—"
    share = 100 * up / played if played else 0
    refused_note = f"; refused: {', '.join(refused)}" if refused else ""
    shares.sort()
    feet = f"{100 * statistics.median(agreement):.0f}%" if agreement else "—"
    pull = f"{100 * shares[len(shares) // 2]:.0f}%, {100 * shares[-1]:.0f}% | " if shares else ("— | " if assisted else "")
    lines.append(f"| {group.name} | {played} | {up} ({share:.0f}%) | {where_up} | {feet} | {pull}"
                 f"{'; '.join(falls) or '—'}{refused_note} |")
text = "\n".join(lines)
Path("execute-trials.md").write_text(text + "\n")
print(text)
PY
echo "table also in $PWD/execute-trials.md" >&2
