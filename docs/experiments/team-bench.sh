#!/usr/bin/env bash
# The swarm-scale benchmark (issue 37, EXPERIMENTS.md): robot-steps per
# second of 1, 10, 100 and 1,000 robots in one world at the density of
# FILE (default examples/aggregation.bat; its last stage), the arena's side
# growing as the square root of the team, beside Enki's figures and
# shaping's own with one robot.
#
#   docs/experiments/team-bench.sh [FILE]     ROUNDS=5 RUNS=5 SIZES="1 10 100 1000"
#
# Each round runs `shaping bench FILE --runs RUNS --set '*.world.robots=N'
# --set '*.world.arena=WxW'` once for every size, the sizes in turn, so that
# what else the machine does falls on all of them alike; the table gives the
# medians over the rounds (each round's figure is itself the median of its
# runs). The stage must let robots start anywhere (no `start`) or in a
# region that holds the largest team: `--set` refuses a team its start
# region cannot hold, naming the setting and how many it holds.
set -euo pipefail
cd "$(dirname "$0")/../.."
FILE=${1:-examples/aggregation.bat}
ROUNDS=${ROUNDS:-5}
RUNS=${RUNS:-5}
SIZES=${SIZES:-1 10 100 1000}
cargo build --release --quiet
B=${CARGO_TARGET_DIR:-target}/release/shaping
OUT=runs/team-bench
mkdir -p "$OUT"

# The density of FILE's last stage: its robots and arena, from the program.
$B build "$FILE" -o "$OUT/program.json" 2> /dev/null
read -r ROBOTS WIDTH DEPTH < <(python3 -c '
import json, sys
w = json.load(open(sys.argv[1]))["stages"][-1]["world"]
print(w.get("robots", 1), w["arena"][0], w["arena"][1])' "$OUT/program.json")
echo "$FILE: $ROBOTS robots in $WIDTH x $DEPTH mm; $ROUNDS rounds of $RUNS runs" >&2

: > "$OUT/lines.jsonl"
for round in $(seq "$ROUNDS"); do
  for n in $SIZES; do
    side=$(python3 -c "import math, sys; print(round(math.sqrt($n * $WIDTH * $DEPTH / $ROBOTS)))")
    nice "$B" bench "$FILE" --runs "$RUNS" --set "*.world.robots=$n" --set "*.world.arena=${side}x${side}" \
      | python3 -c "import json, sys; v = json.loads(sys.stdin.read()); v.update(round=$round, side=$side); print(json.dumps(v))" \
      >> "$OUT/lines.jsonl"
  done
  echo "round $round done" >&2
done

python3 - "$OUT/lines.jsonl" <<'EOF'
import json, statistics, sys

lines = [json.loads(l) for l in open(sys.argv[1])]
# Enki (issue 37): its stock Khepera, 8 IR read every step, constant
# density, 0.1 s steps, no objects; robot-steps per second.
enki = {1: 1.2e6, 10: 1.0e6, 100: 0.55e6, 1000: 0.06e6}
sizes = sorted({l["robots"] for l in lines})
med = {}
for n in sizes:
    mine = [l for l in lines if l["robots"] == n]
    med[n] = {
        "rate": statistics.median(l["robot_steps_per_sec"] for l in mine),
        "side": mine[0]["side"],
        "moving": statistics.median(l["sim_moving_share"] for l in mine),
        "colliding": statistics.median(l["sim_collision_share"] for l in mine),
        "rounds": len(mine),
    }
one = med.get(1, {}).get("rate")

def m(x):
    return f"{x / 1e6:.2f} M"

print("| robots | arena, mm | robot-steps/s | Enki | x Enki | / own 1 robot | moving | colliding |")
print("|---|---|---|---|---|---|---|---|")
for n in sizes:
    r = med[n]
    e = enki.get(n)
    vs_enki = f"{r['rate'] / e:.1f} x" if e else "-"
    vs_one = f"{r['rate'] / one:.2f}" if one else "-"
    print(f"| {n:,} | {r['side']:,} x {r['side']:,} | {m(r['rate'])} | {m(e) if e else '-'} | "
          f"{vs_enki} | {vs_one} | {r['moving']:.3f} | {r['colliding']:.3f} |")

def goal(text, value, target):
    if value is None:
        print(f"- {text}: not measured")
        return
    verdict = "met" if value >= target else f"missed by {(1 - value / target) * 100:.0f}%"
    print(f"- {text}: {value:.2f} against {target}: {verdict}")

print()
rate = lambda n: med[n]["rate"] if n in med else None
x = lambda n: rate(n) / enki[n] if rate(n) else None
goal("100 robots, x Enki", x(100), 10)
goal("1,000 robots, x Enki", x(1000), 50)
goal("1,000 robots, / own 1 robot", rate(1000) / one if rate(1000) and one else None, 0.5)
EOF
