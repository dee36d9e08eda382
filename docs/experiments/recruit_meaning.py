"""What recruit.bat's signal means, per seed (EXPERIMENTS.md, "Recruitment").

    python3 docs/experiments/recruit_meaning.py DIR

DIR is the experiment's directory (`shaping experiment examples/recruit.bat
--out DIR`). For every `DIR/seed-N`, it reads the test stage
`forage_silent`: its 20 lives with the signals (the world before the
change, the lives of `forage_test`), then the same 20 lives with every
broadcast heard as 0 (after). One line per seed:

- what the robots broadcast on the food and off it (mean of `signal[0]`,
  lives with signals);
- the share of the actions off the food in which a robot hears more than
  0.5 in some sector (lives with signals);
- approach: how far robots off the food, 150 to 450 mm from the food's
  centre, come closer to it in the next 10 actions, in mm (mean; negative:
  closer), with the signals and silenced, in the same lives.

Standard library only; reads `episode.json` for each life's food zone (the
zone of grey 0) and its first action, and `trace.csv`.
"""

import bisect
import csv
import json
import math
import statistics
import sys
from pathlib import Path

AHEAD = 10  # actions
BAND = (150.0, 450.0)  # mm from the food's centre


def seed_line(stage_dir: Path) -> str:
    episode = json.loads((stage_dir / "episode.json").read_text())
    lives = []  # (first action, food centre, silenced)
    for world in episode["worlds"]:
        [food] = [z for z in world["zones"] if z["grey"] == 0.0 and not z["charger"]]
        centre = ((food["from"][0] + food["to"][0]) / 2, (food["from"][1] + food["to"][1]) / 2)
        lives.append((int(world["from"]), centre, world["stage"] == stage_dir.name))
    rows = {}
    with open(stage_dir / "trace.csv") as f:
        for row in csv.DictReader(f):
            heard = max(float(v) for k, v in row.items() if k.startswith("heard["))
            rows[(int(row["action"]), int(row["robot"]))] = (
                float(row["x"]), float(row["y"]), float(row["floor[0]"]) < 0.5, heard, float(row["signal[0]"]))
    firsts = [first for first, _, _ in lives]
    ends = firsts[1:] + [1 + max(a for a, _ in rows)]
    signal = {True: [], False: []}
    hearing = []
    approach = {False: [], True: []}  # silenced -> changes
    for (a, r), (x, y, on_food, heard, sent) in rows.items():
        life = bisect.bisect_right(firsts, a) - 1
        if life < 0:
            continue
        _, centre, silenced = lives[life]
        end = ends[life]
        if not silenced:
            signal[on_food].append(sent)
            if not on_food:
                hearing.append(heard > 0.5)
        later = rows.get((a + AHEAD, r))
        if on_food or later is None or a + AHEAD >= end:
            continue
        d0 = math.dist((x, y), centre)
        if BAND[0] <= d0 <= BAND[1]:
            approach[silenced].append(math.dist(later[:2], centre) - d0)
    mean = lambda v: statistics.mean(v) if v else float("nan")
    return (f"broadcast on food {mean(signal[True]):.2f}, off {mean(signal[False]):.2f}; "
            f"off food hearing > 0.5 in {mean(hearing):.2f} of actions; "
            f"approach in {AHEAD} actions {mean(approach[False]):+.1f} mm with signals, "
            f"{mean(approach[True]):+.1f} mm silenced")


def main() -> None:
    if len(sys.argv) != 2:
        sys.exit("usage: recruit_meaning.py DIR")
    root = Path(sys.argv[1])
    seeds = sorted((int(p.name[5:]), p) for p in root.glob("seed-*") if p.name[5:].isdigit())
    if not seeds:
        sys.exit(f"recruit_meaning.py: `{root}` has no seed-N directories")
    for n, path in seeds:
        print(f"seed {n}: {seed_line(path / 'forage_silent')}")


if __name__ == "__main__":
    main()
