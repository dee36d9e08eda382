"""Prints the figures of EXPERIMENTS.md from the files docs/experiments/run.sh wrote.

Usage: python3 docs/experiments/analyse.py RUNS_DIR SEEDS
"""

import csv
import json
import re
import statistics
import sys

R, N = sys.argv[1], int(sys.argv[2])
SEEDS = range(1, N + 1)


def spread(v, digits=2):
    v = [x for x in v if x is not None]
    if not v:
        return "-"
    f = f"{{:.{digits}f}}"
    return f"{f.format(statistics.median(v))} ({f.format(min(v))}..{f.format(max(v))})"


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def history(run, seed, stage):
    return [float(r["best"]) for r in rows(f"{R}/{run}/seed-{seed}/{stage}/generations.csv") if r["stage"] == stage]


def roll3(b):
    return [sum(b[max(0, i - 2): i + 1]) / len(b[max(0, i - 2): i + 1]) for i in range(len(b))]


def first_reach(v, level):
    return next((i + 1 for i, x in enumerate(v) if x >= level), None)


# ---------------------------------------------------------------- replays
REPLAY = re.compile(
    r"^(\S+) (\S+) (\d+) (\d+) (\S+) \S+: (\d+) actions, fitness ([-\d.]+), (\d+) grips, (\d+) released outside, (\d+) recharges"
)
replays = []
with open(f"{R}/replays.txt") as f:
    for line in f:
        m = REPLAY.match(line)
        if m:
            run, stage, seed, ep, mode, actions, fit, grips, out, rech = m.groups()
            replays.append(dict(run=run, stage=stage, seed=int(seed), ep=int(ep), mode=mode, actions=int(actions),
                                fitness=float(fit), grips=int(grips), out=int(out), recharges=int(rech)))


def sel(run, stage, mode="learning"):
    return [r for r in replays if r["run"] == run and r["stage"] == stage and r["mode"] == mode]


def recharge_share(run, stage):
    v = sel(run, stage)
    return sum(1 for r in v if r["recharges"] > 0), len(v)


print("\n== figure 5: avoid.bat, performance indicator at action 300 (and 100, 1000)")
at = {100: [], 300: [], 1000: []}
for s in SEEDS:
    perf = [float(r["perf_avoid"]) for r in rows(f"{R}/avoid-{s}/avoid/trace.csv")]
    for k in at:
        at[k].append(perf[k - 1] if len(perf) >= k else None)
    print(f"  seed {s}: " + " ".join(f"{perf[k - 1]:+.2f}" for k in (50, 100, 200, 300, 500, 1000) if len(perf) >= k))
for k, v in at.items():
    print(f"  at action {k}: {spread(v)}")

for run in ("khepera", "khepera-explore", "pretrained", "forward-only"):
    print(f"\n== figure 4: {run}, navigation")
    r25, r40, rlast, reach, ever = [], [], [], [], []
    for s in SEEDS:
        b = history(run, s, "navigation")
        r = roll3(b)
        r25.append(r[24])
        r40.append(r[39])
        rlast.append(r[-1])
        reach.append(first_reach(r, 0.70))
        ever.append(max(b))
    last = f"; at the last ({len(b)}): {spread(rlast, 3)}" if len(b) > 40 else ""
    print(f"  best, 3-generation rolling mean, at generation 25: {spread(r25, 3)}; at 40: {spread(r40, 3)}{last}")
    print(f"  best ever: {spread(ever, 3)}; generation where the rolling best reaches 0.70: {reach}")
    ok, tot = recharge_share(run, "navigation")
    fits = [r["fitness"] for r in sel(run, "navigation")]
    print(f"  chosen best, replays: recharges in {ok} of {tot} ({100 * ok / max(tot, 1):.0f}%); fitness {spread(fits, 3)}")


def grip_signals(path):
    t = rows(path)
    if not t or "reinf_grip" not in t[0]:
        return []
    return [(int(r["action"]), float(r["reinf_grip"])) for r in t if float(r["reinf_grip"]) != 0.0]


def grip_decisions(path):
    """(grip's activation, the highest other activation, its reinforcement)
    at the first action of every run of the grip script that was judged."""
    t = rows(path)
    others = [c for c in t[0] if c.startswith("act_") and c != "act_grip"]
    out = []
    for i, r in enumerate(t):
        if r["winner"] != "grip" or (i > 0 and t[i - 1]["winner"] == "grip"):
            continue
        for q in t[i:]:
            if q["winner"] != "grip":
                break
            if float(q["reinf_grip"]) != 0.0:
                out.append((float(r["act_grip"]), max(float(r[c]) for c in others), 1 if float(q["reinf_grip"]) > 0 else -1))
                break
    return out


def coverage(path):
    """50 mm squares of the arena the robot's centre visited (of 96)."""
    return len({(int(float(r["x"]) // 50), int(float(r["y"]) // 50)) for r in rows(path)})


def won_per_life(run, stage):
    """Actions each module drove, per replay (mean over the replays)."""
    count, lives = {}, 0
    for s in SEEDS:
        for ep in (101, 102, 103):
            lives += 1
            for r in rows(f"{R}/replay-{run}-{stage}-{s}-{ep}/trace.csv"):
                count[r["winner"]] = count.get(r["winner"], 0) + 1
    return ", ".join(f"{k} {v / lives:.0f}" for k, v in sorted(count.items(), key=lambda kv: -kv[1]))


def bigger_trace(run, s, stage="bigger"):
    """The rows of a seed's test stage and the action where the world changed."""
    with open(f"{R}/{run}/seed-{s}/{stage}/summary.json") as f:
        switch = json.load(f)["before"]["actions"]
    return rows(f"{R}/{run}/seed-{s}/{stage}/trace.csv"), switch


def summary(run, s, stage):
    with open(f"{R}/{run}/seed-{s}/{stage}/summary.json") as f:
        return json.load(f)


def grip_signals_by_life(run, s, stage="bigger"):
    """The grip module's reinforcement signals of a seed's many-lives test, as
    (life, signal) in order (lives 0..L-1 before the change, L..2L-1 after),
    and the test's summary.json."""
    sm = summary(run, s, stage)
    life = [i for i, n in enumerate(sm["before_lives"] + sm["after_lives"]) for _ in range(n)]
    t = rows(f"{R}/{run}/seed-{s}/{stage}/trace.csv")
    assert len(t) == len(life), f"{run} seed {s}: {len(t)} rows, lives add up to {len(life)}"
    return [(life[i], float(r["reinf_grip"])) for i, r in enumerate(t) if float(r["reinf_grip"]) != 0.0], sm


def figure13(run, title, stage="bigger"):
    """The old criterion, seed by seed: a drop of 0.2 or more within 100
    actions of the change, and back within 0.1 of the level before at the end."""
    print(f"\n== figure 13, the old criterion: {title}")
    drops = recov = 0
    for s in SEEDS:
        t, switch = bigger_trace(run, s, stage)
        perf = [float(r["perf_grip"]) for r in t]
        sig = [float(r["reinf_grip"]) for r in t]
        n_before = sum(1 for x in sig[:switch] if x)
        n_after = sum(1 for x in sig[switch:] if x)
        before = perf[switch - 1] if switch > 0 else 0.0
        after = perf[switch: switch + 100]
        low = min(after) if after else before
        end = perf[-1]
        d = before - low >= 0.2
        rcv = d and abs(end - before) <= 0.1
        drops += d
        recov += rcv
        print(f"  seed {s}: grip signals {n_before} before, {n_after} after; performance before {before:+.2f}, lowest in the first 100 after {low:+.2f}, at the end {end:+.2f}; drop {d}, recovery {rcv}")
    print(f"  seeds with a drop of 0.2 or more: {drops} of {N}; with recovery within 0.1: {recov} of {N}")


for run in ("khepera", "khepera-explore", "khepera-practice"):
    print(f"\n== figures 9 and 11: {run} collect, chosen best replays (300 actions)")
    for mode in ("learning", "nolearning"):
        v = sel(run, "collect", mode)
        print(f"  {mode}: released outside per replay {spread([r['out'] for r in v], 1)} (mean {statistics.mean([r['out'] for r in v]):.2f}); "
              f"grips {spread([r['grips'] for r in v], 1)}; fitness {spread([r['fitness'] for r in v], 3)}; "
              f"recharge in {sum(1 for r in v if r['recharges'] > 0)} of {len(v)}")
    best = [history(run, s, "collect") for s in SEEDS]
    print(f"  collect best at its last generation: {spread([b[-1] for b in best], 3)}; best ever {spread([max(b) for b in best], 3)}")
    for stage in ("navigation", "collect"):
        cov = [coverage(f"{R}/replay-{run}-{stage}-{s}-{ep}/trace.csv") for s in SEEDS for ep in (101, 102, 103)]
        print(f"  {stage} replays: 50 mm squares visited {spread(cov, 0)} of 96; actions won per life: {won_per_life(run, stage)}")

    print(f"\n== grip attempts at walls inside the architecture, {run} (punished grip attempts / all grip attempts)")
    for mode, tag in (("learning", ""), ("nolearning", "nl-")):
        pun = tot = early_p = early_t = late_p = late_t = 0
        for s in SEEDS:
            for ep in (101, 102, 103):
                for a, r in grip_signals(f"{R}/replay-{run}-collect-{tag}{s}-{ep}/trace.csv"):
                    tot += 1
                    pun += r < 0
                    if a < 150:
                        early_t += 1
                        early_p += r < 0
                    else:
                        late_t += 1
                        late_p += r < 0
        share = lambda p, t: f"{p}/{t} = {p / t:.2f}" if t else "-"
        print(f"  {mode}: all {share(pun, tot)}; actions 0-149 {share(early_p, early_t)}; 150-299 {share(late_p, late_t)}")
    acts = {1: [], -1: []}
    runner_up = []
    for s in SEEDS:
        for ep in (101, 102, 103):
            for y, other, r in grip_decisions(f"{R}/replay-{run}-collect-{s}-{ep}/trace.csv"):
                acts[r].append(y)
                runner_up.append(other)
    print(f"  learning: the grip module's activation where an attempt starts: rewarded {spread(acts[1], 3)}, punished {spread(acts[-1], 3)}; "
          f"the highest other module's {spread(runner_up, 3)}")

# The target for khepera-practice.bat: each seed's 3 fresh replays.
v = sel("khepera-practice", "collect")
print("\n== khepera-practice collect replays, per seed (seeds 101, 102, 103): released outside")
for s in SEEDS:
    print(f"  seed {s:2d}: {' '.join(str(r['out']) for r in v if r['seed'] == s)}")
outs = [r["out"] for r in v]
print(f"  median {statistics.median(outs)}, best {max(outs)}, mean {statistics.mean(outs):.2f} over {len(outs)} replays "
      f"(target: median >= 3, one replay >= 5)")


for run in ("khepera", "khepera-explore"):
    figure13(run, f"{run} bigger (one life of 300 actions after 300 before; objects 10 -> 25 mm, learning only)")
figure13("khepera-practice", "khepera-practice bigger (40 + 40 lives; objects 10 -> 25 mm, learning only)")


# ---------------------------------------------------------------- figure 13, restated
# From the run directories alone: each test's summary.json counts, per life,
# the grip module's rewards and punishments (reinforcement_counts).
GRIP = "grip (activation)"
BLOCK = 10


def mean_signal(counts, lives):
    """(rewards - punishments) / (rewards + punishments) over the given lives, None without signals."""
    r = sum(counts["rewards"][i] for i in lives)
    p = sum(counts["punishments"][i] for i in lives)
    return (r - p) / (r + p) if r + p else None


def restated(run, title, learn="bigger", control="bigger_nolearning", unchanged="bigger_unchanged"):
    print(f"\n== figure 13, the restated criterion: {title}")
    counted = readapted = 0
    out_l = out_nl = 0
    gaps = []
    for s in SEEDS:
        sl, snl, su = summary(run, s, learn), summary(run, s, control), summary(run, s, unchanged)
        L = sl["lives"]
        cl, cnl, cu = (x["reinforcement_counts"][GRIP] for x in (sl, snl, su))
        bl, al = mean_signal(cl["before"], range(L)), mean_signal(cl["after"], range(L))
        bn, an = mean_signal(cnl["before"], range(L)), mean_signal(cnl["after"], range(L))
        drop_nl = None if None in (bn, an) else bn - an
        diff_l = None if None in (bl, al) else bl - al
        count = drop_nl is not None and drop_nl >= 0.1
        re = count and diff_l is not None and diff_l <= drop_nl / 2
        counted += count
        readapted += re
        ol, onl = sl["after"]["releases_outside"], snl["after"]["releases_outside"]
        out_l += ol
        out_nl += onl
        gap = []
        for k in range(L // BLOCK):
            lives = range(k * BLOCK, (k + 1) * BLOCK)
            a, b = mean_signal(cl["after"], lives), mean_signal(cu["after"], lives)
            gap.append(None if None in (a, b) else a - b)
        gaps.append(gap)
        f = lambda x: "  -  " if x is None else f"{x:+.2f}"
        need = "" if not count else f" (needs <= {drop_nl / 2:+.2f}: {'met' if re else f'missed by {diff_l - drop_nl / 2:.2f}'})"
        print(f"  seed {s:2d}: without learning {f(bn)} -> {f(an)}, drop {f(drop_nl)}{' counted' if count else ' not counted'}; "
              f"with learning {f(bl)} -> {f(al)}, difference {f(diff_l)}{need}; "
              f"released outside per life after the change {ol / L:.2f} with learning, {onl / L:.2f} without")
    share = out_l / out_nl if out_nl else float("nan")
    print(f"  seeds counted (drop without learning >= 0.1): {counted} of {N} (target >= 7); "
          f"re-adaptation on {readapted} of {counted} counted (target >= 7)")
    print(f"  task kept: released outside per life after the change, with learning {out_l / (N * L):.2f}, "
          f"without {out_nl / (N * L):.2f}: {100 * share:.0f}% (target >= 75%)")
    cols = [[g[k] for g in gaps if g[k] is not None] for k in range(len(gaps[0]))]
    print(f"  with learning minus unchanged, each block of {BLOCK} lives after the change, median over seeds "
          f"(lower on n seeds): " + "; ".join(f"{statistics.median(c):+.2f} ({sum(1 for x in c if x < 0)})" for c in cols))


restated("khepera-practice", "khepera-practice.bat, 40 + 40 lives, objects 10 -> 25 mm, paired with learning off and with no change")


# Figure 13 over many lives, block by block: khepera-practice's three tests
# (the same lives), and f13-at25 (the same architecture with 25 mm objects
# from its training stage on: its `bigger` keeps 25 mm, its
# `bigger_unchanged` goes from 25 to 10 mm).
mean_or_none = lambda v: statistics.mean(v) if v else None
with_mean = lambda v: f"{spread(v)} (mean over seeds {statistics.mean([x for x in v if x is not None]):+.2f})"
first30, last30, per_block = {}, {}, {}
TESTS = (("long", "khepera-practice", "bigger", "objects 10 -> 25 mm, learning"),
         ("control", "khepera-practice", "bigger_unchanged", "objects stay 10 mm, learning"),
         ("nolearning", "khepera-practice", "bigger_nolearning", "objects 10 -> 25 mm, no learning"),
         ("at25", "f13-at25", "bigger", "25 mm objects from the training stage on, no change, learning"),
         ("at25-to10", "f13-at25", "bigger_unchanged", "f13-at25's bests, objects 25 -> 10 mm, learning"))
for key, run, stage, what in TESTS:
    print(f"\n== figure 13 over many lives: {run} {stage}, 40 + 40 lives of 300 actions; {what}")
    by_life = [grip_signals_by_life(run, s, stage) for s in SEEDS]
    lives = len(by_life[0][1]["before_lives"])
    before = [[x for l, x in sig if l < lives] for sig, _ in by_life]
    after = [[x for l, x in sig if l >= lives] for sig, _ in by_life]
    pre = [mean_or_none(v[-30:]) for v in before]
    first = first30[key] = [mean_or_none(v[:30]) for v in after]
    last = last30[key] = [mean_or_none(v[-30:]) for v in after]
    up = sum(1 for a, b in zip(first, last) if a is not None and b is not None and b > a)
    print(f"  grip signals before the change {spread([len(v) for v in before], 0)}, after it {spread([len(v) for v in after], 0)}")
    print(f"  mean of the last 30 signals before the change {with_mean(pre)}; of the first 30 after {with_mean(first)}; "
          f"of the last 30 {with_mean(last)}; the last 30 above the first 30 on {up} of {N} seeds")
    per_seed = [[mean_or_none([x for l, x in sig if k * BLOCK <= l < (k + 1) * BLOCK]) for k in range(2 * lives // BLOCK)]
                for sig, _ in by_life]
    nb, half = 2 * lives // BLOCK, lives // BLOCK
    per_block[key] = (per_seed, half)
    for name, f in (("median", statistics.median), ("mean", statistics.mean)):
        col = [f([p[k] for p in per_seed if p[k] is not None]) for k in range(nb)]
        print(f"  {name} over seeds of the mean grip signal per block of {BLOCK} lives: "
              f"{' '.join(f'{x:+.2f}' for x in col[:half])} | {' '.join(f'{x:+.2f}' for x in col[half:])}")
    out_per_life = [(sm["before"]["releases_outside"] / len(sm["before_lives"]),
                     sm["after"]["releases_outside"] / len(sm["after_lives"])) for _, sm in by_life]
    print(f"  released outside per life, before the change {spread([a for a, _ in out_per_life])}, "
          f"after it {spread([b for _, b in out_per_life])}")
for key in ("long", "nolearning"):
    (test, half), (control, _) = per_block[key], per_block["control"]
    cells = []
    for k in range(half, len(test[0])):
        d = [a[k] - b[k] for a, b in zip(test, control) if a[k] is not None and b[k] is not None]
        cells.append(f"{statistics.median(d):+.2f} (lower on {sum(1 for x in d if x < 0)} of {len(d)})")
    print(f"  paired by seed, each block of {BLOCK} lives after the change, {key} minus control (median): {'; '.join(cells)}")


# The same bests with grip and release networks trained with 25 mm objects,
# and with the test learning at other CRBP rates (docs/experiments/lives.rs:
# one line per life, `key value` pairs).
def lives_of(name):
    by_seed = {}
    with open(f"{R}/{name}.txt") as f:
        for line in f:
            w = line.split()
            x = dict(zip(w[0::2], w[1::2]))
            by_seed.setdefault(int(x["seed"]), []).append(x)
    return [by_seed[s] for s in SEEDS]


def block_means(lives):
    """Per seed, the mean grip signal of each block of BLOCK lives (None without signals)."""
    out = []
    for ls in lives:
        row = []
        for k in range(0, len(ls), BLOCK):
            n = sum(int(x["signals"]) for x in ls[k:k + BLOCK])
            row.append(sum(float(x["sum"]) for x in ls[k:k + BLOCK]) / n if n else None)
        out.append(row)
    return out


# The tool runs the tests' own lives: it must agree with them life by life.
for v in ("bigger", "bigger_unchanged", "bigger_nolearning"):
    for s, ls in zip(SEEDS, lives_of(f"lives-{v}")):
        sig, sm = grip_signals_by_life("khepera-practice", s, v)
        for i, x in enumerate(ls):
            mine = [y for l, y in sig if l == i]
            assert (int(x["actions"]), int(x["signals"]), float(x["sum"])) == \
                ((sm["before_lives"] + sm["after_lives"])[i], len(mine), sum(mine)), f"lives-{v} seed {s} life {i}"
print(f"\n== figure 13: what learning in the test does (lives.rs; the tests' own lives, which it reproduces, and variants)")
print(f"  median over seeds of the mean grip signal per block of {BLOCK} lives, 4 before the change | 4 after; "
      f"signals per seed and block; released outside per life before / after")
lives_blocks = {}
for name, what in (("lives-bigger", "bigger: 10 -> 25 mm, CRBP 0.5 / 0.1 (collect's)"),
                   ("lives-bigger_unchanged", "bigger_unchanged: stays 10 mm, 0.5 / 0.1"),
                   ("lives-bigger_nolearning", "bigger_nolearning: 10 -> 25 mm, no learning"),
                   ("lives-bigger-practice25", "networks trained with 25 mm objects, 10 -> 25 mm, 0.5 / 0.1"),
                   ("lives-bigger_unchanged-practice25", "networks trained with 25 mm objects, stays 10 mm, 0.5 / 0.1"),
                   ("lives-bigger_nolearning-practice25", "networks trained with 25 mm objects, 10 -> 25 mm, no learning"),
                   ("lives-bigger-0.25", "10 -> 25 mm, the test learns at 0.5 / 0.25"),
                   ("lives-bigger_unchanged-0.25", "stays 10 mm, 0.5 / 0.25"),
                   ("lives-bigger-0.5", "10 -> 25 mm, the test learns at 0.5 / 0.5"),
                   ("lives-bigger_unchanged-0.5", "stays 10 mm, 0.5 / 0.5")):
    lives = lives_of(name)
    per_seed = lives_blocks[name] = block_means(lives)
    nb = len(per_seed[0])
    col = [statistics.median([p[k] for p in per_seed if p[k] is not None]) for k in range(nb)]
    n = [statistics.mean([sum(int(x["signals"]) for x in ls[k * BLOCK:(k + 1) * BLOCK]) for ls in lives]) for k in range(nb)]
    half = len(lives[0]) // 2
    out = [statistics.mean([sum(int(x["out"]) for x in ls[h * half:(h + 1) * half]) / half for ls in lives]) for h in (0, 1)]
    print(f"  {what}:\n    {' '.join(f'{x:+.2f}' for x in col[:nb // 2])} | {' '.join(f'{x:+.2f}' for x in col[nb // 2:])}"
          f"; signals {' '.join(f'{x:.0f}' for x in n)}; released outside per life {out[0]:.2f} / {out[1]:.2f}")

print("\n== shaping vs evolution from scratch, whole task (criterion: best of a generation >= 3.0)")
sh, sc = [], []
for s in SEEDS:
    col = history("khepera", s, "collect")
    g = first_reach(col, 3.0)
    # navigation's 40 generations, then collect's; the training life is 1000 actions, about 3 evaluations.
    sh.append(None if g is None else 100 * (40 + g) + 1000 / 300)
    full = history("scratch-full", s, "full")
    g2 = first_reach(full, 3.0)
    sc.append(None if g2 is None else 100 * g2)
print(f"  evaluations, shaping (khepera.bat): {spread(sh, 0)}; from scratch (scratch-full.bat): {spread(sc, 0)}")
ms, mc = statistics.median([x for x in sh if x]), statistics.median([x for x in sc if x])
print(f"  ratio of medians shaping / scratch: {ms / mc:.2f}")
for run, stage in (("khepera", "collect"), ("scratch-full", "full")):
    v = sel(run, stage)
    print(f"  chosen best of {run}: fitness {spread([r['fitness'] for r in v], 3)}, released outside per replay "
          f"{spread([r['out'] for r in v], 1)} (mean {statistics.mean([r['out'] for r in v]):.2f}), recharge in "
          f"{sum(1 for r in v if r['recharges'] > 0)} of {len(v)}")
    fin = [history(run, s, stage)[-1] for s in SEEDS]
    print(f"  final best of {run}: {spread(fin, 3)}")


# ---------------------------------------------------------------- Floreano & Mondada, the 10x claim
def reliable_recharge(run, stage, battery, life):
    """First generation (1-based) from which the generation's best recharges
    in 3 generations in a row. "Recharges": its evaluation counted a recharge
    and its fitness is above battery / life, the most a life that ends with
    its first battery can score (fitness per action at most 1 / life), so
    the life outlived the battery. None if it never happens."""
    out = []
    for s in SEEDS:
        g = [r for r in rows(f"{R}/{run}/seed-{s}/{stage}/generations.csv") if r["stage"] == stage]
        ok = [int(r["best_recharges"]) > 0 and float(r["best"]) > battery / life for r in g]
        out.append(next((i + 1 for i in range(len(ok) - 2) if all(ok[i:i + 3])), None))
    return out


print("\n== Floreano & Mondada 1994: obstacle avoidance from scratch (best fitness per generation)")
b94 = [history("fm1994", s, "avoidance") for s in SEEDS]
print(f"  best at generation 10: {spread([b[9] for b in b94], 3)}; at the last ({len(b94[0])}): {spread([b[-1] for b in b94], 3)}")

print("\n== Floreano & Mondada 1996: homing from scratch; the paper's 10x claim")
fm = reliable_recharge("fm1996", "homing", 50, 150)
nav = reliable_recharge("khepera", "navigation", 200, 300)
b96 = [history("fm1996", s, "homing") for s in SEEDS]
print(f"  F&M 1996 best fitness at generation 40: {spread([b[39] for b in b96], 3)}; at 240: {spread([b[-1] for b in b96], 3)}")
print(f"  first generation of reliable recharging (3 in a row), F&M 1996 from scratch: {fm}")
print(f"  the same, khepera.bat navigation (shaped): {nav}")
def med(v):
    # A seed that never got there counts as one generation past the end
    # (a lower bound), so the median stays defined.
    return statistics.median(v)
fm_c = [x if x is not None else 241 for x in fm]
nav_c = [x if x is not None else 41 for x in nav]
print(f"  medians (never = past the last generation): from scratch {med(fm_c)}, shaped {med(nav_c)}; "
      f"ratio {med(fm_c) / med(nav_c):.2f} (the paper: 240 / 40 = 6)")

print("\n== the charger example of docs/language.md (section 18): recharges of the last generation's best")
ch = [int(rows(f"{R}/charger/seed-{s}/s/generations.csv")[-1]["best_recharges"]) for s in SEEDS]
fin = [history("charger", s, "s")[-1] for s in SEEDS]
print(f"  best_recharges per seed: {' '.join(map(str, ch))}; median {statistics.median(ch)}; final best {spread(fin, 1)}")

print("\n== the T-maze (examples/t-maze.bat): share of 100 fresh lives in the cued arm, per seed")
for net, run in [("recurrent", "t-maze"), ("feedforward", "t-maze-ff")]:
    shares, per = [], []
    for s in SEEDS:
        with open(f"{R}/{run}/seed-{s}/maze_test/summary.json") as f:
            d = json.load(f)
        shares.append(d["fitness"])
        per.append("/".join(f"{v['fitness']:.2f}" for v in d["after_variants"]))
    print(f"  {net}: {' '.join(f'{x:.2f}' for x in shares)}; median {statistics.median(shares):.2f}, "
          f"seeds at 0.8 or more: {sum(x >= 0.8 for x in shares)}")
    print(f"    per variant (left/right): {' '.join(per)}")


# ---------------------------------------------------------------- a team shaped stage by stage
def mann_whitney(a, b):
    """Two-sided Mann-Whitney U (U of `a`), normal approximation with tie and
    continuity corrections (as `shaping compare` without an exact case), and
    the Vargha-Delaney A12 (the chance that a value of `a` is the larger)."""
    pooled = sorted(a + b)
    rank = {}
    for x in set(pooled):
        first = pooled.index(x)
        rank[x] = first + (pooled.count(x) + 1) / 2
    n1, n2 = len(a), len(b)
    u = sum(rank[x] for x in a) - n1 * (n1 + 1) / 2
    n = n1 + n2
    ties = sum(pooled.count(x) ** 3 - pooled.count(x) for x in set(pooled))
    var = n1 * n2 / 12 * ((n + 1) - ties / (n * (n - 1)))
    z = (abs(u - n1 * n2 / 2) - 0.5) / var ** 0.5 if var > 0 else 0.0
    p = min(1.0, 2 * (1 - statistics.NormalDist().cdf(max(z, 0.0))))
    a12 = sum((x > y) + 0.5 * (x == y) for x in a for y in b) / (n1 * n2)
    return u, p, a12


print("\n== a team shaped stage by stage (shaped-team.bat) against evolution from scratch (shaped-team-scratch.bat)")
CRIT, POP, EVALS = 0.43, 40, 2
# The shaped file's explore and home stages (40 generations each) are spent
# before escort; a seed that never reaches the criterion counts at the last
# generation plus one (as `shaping compare`), after every seed that does.
ev = {}
for run, before, gens in (("shaped-team", 80, 40), ("shaped-team-scratch", 0, 120)):
    e, test = [], []
    for s in SEEDS:
        g = first_reach(history(run, s, "escort"), CRIT)
        e.append(POP * EVALS * (before + (g if g is not None else gens + 1)))
        with open(f"{R}/{run}/seed-{s}/check/summary.json") as f:
            test.append(json.load(f)["fitness"])
    reached = sum(x < POP * EVALS * (before + gens + 1) for x in e)
    ev[run] = e
    print(f"  {run}: evaluations to escort >= {CRIT}: {' '.join(map(str, e))}; median {statistics.median(e):.0f}; "
          f"{reached} of {len(e)} seeds reach it")
    print(f"    test fitness per seed: {' '.join(f'{x:.3f}' for x in test)}")
u, p, a12 = mann_whitney(ev["shaped-team"], ev["shaped-team-scratch"])
print(f"  evaluations, shaped against scratch: U = {u:g}, p = {p:.4f}" if p >= 0.001 else f"  evaluations, shaped against scratch: U = {u:g}, p = {p:.1e}", end="")
print(f", A12 = {a12:.3f} (below 0.5: shaped needs fewer)")
# Why, by role: the scouts' fitness per life in check's lives after the
# change (navigation's per-action term from the trace), the guards' (the
# team's mean holds 2 scouts and 2 guards), and the recharges.
for run in ("shaped-team", "shaped-team-scratch"):
    scouts, guards, recharges = [], [], []
    for s in SEEDS:
        with open(f"{R}/{run}/seed-{s}/check/summary.json") as f:
            d = json.load(f)
        skip = sum(d["before_lives"])
        fit = 0.0
        for r in rows(f"{R}/{run}/seed-{s}/check/trace.csv"):
            if int(r["action"]) >= skip and int(r["robot"]) < 2:
                ir = max(float(r[f"ir[{k}]"]) for k in range(8))
                fit += abs(float(r["wheels[0]"]) + float(r["wheels[1]"])) / 2 * (1 - ir) / 300
        scouts.append(fit / 2 / len(d["after_lives"]))
        guards.append(2 * d["fitness"] - scouts[-1])
        recharges.append(d["after"]["recharges"])
    print(f"  {run}, per life: a scout {' '.join(f'{x:.2f}' for x in scouts)}; a guard "
          f"{' '.join(f'{x:.2f}' for x in guards)}; recharges in 20 lives {' '.join(map(str, recharges))}")


print("\n== when shaping pays: objects released outside per fresh life (walkers.rs, 20 lives per seed, learning on)")
# Added after the ladder ran, beside its stated final test `exam` (whose
# lives carry what learning acquired from life to life): each seed's chosen
# best in 20 fresh lives, each starting from the genome, as in evolution.
for b in (200, 120, 80):
    out = {}
    for f in ("shaped", "scratch"):
        with open(f"{R}/ladder-{b}-{f}-lives.txt") as fh:
            out[f] = [float(m.group(1)) for m in re.finditer(r"^seed \d+ \(medians.*objects out per life ([0-9.]+)", fh.read(), re.M)]
        print(f"  battery {b}, {f}: {' '.join(f'{x:.2f}' for x in out[f])}; median {statistics.median(out[f]):.3f}")
    u, p, a12 = mann_whitney(out["shaped"], out["scratch"])
    print(f"  battery {b}: U = {u:g}, p = {p:.4f}, A12 = {a12:.3f} (above 0.5: shaped releases more)")
