#!/usr/bin/env bash
# Regenerates every number and picture of EXPERIMENTS.md (a few minutes on
# two cores). Results go to runs/experiments/; the pictures EXPERIMENTS.md
# shows are copied next to this script.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
B=target/release/shaping
R=runs/experiments
D=docs/experiments
mkdir -p "$R"

# Figures 4 and 9 (and the test stage of figure 13), five seeds.
$B experiment examples/khepera.bat --seeds 5 --out $R/khepera --fresh --criterion navigation=0.5
# The from-scratch baselines, same seeds, same criterion.
$B experiment examples/scratch.bat --seeds 5 --out $R/scratch --fresh --criterion scratch=0.5
$B experiment examples/monolithic.bat --seeds 5 --out $R/monolithic --fresh --criterion mono=0.5

# The evolved bests at work: three fresh episodes each.
for stage in navigation collect; do
  for s in 1 2 3 4 5; do
    for r in 101 102 103; do
      echo -n "$stage seed $s episode $r: "
      $B replay examples/khepera.bat --stage $stage --run $R/khepera/seed-$s --seed $r \
        --out $R/replay-$stage-$s-$r | sed 's/ -> .*//'
    done
  done
done

# Figure 5: the avoid module alone, learning for 5000 actions, five seeds.
# Printed: the mean performance per block of 500 actions.
for s in 1 2 3 4 5; do
  $B replay examples/avoid.bat --seed $s --out $R/avoid-$s > /dev/null
  awk -F, -v s=$s 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "perf_avoid") c = i; next }
    { sum += $c; n++; if (n == 500) { line = line sprintf(" %5.2f", sum / n); sum = 0; n = 0 } }
    END { print "avoid seed " s ":" line }' $R/avoid-$s/trace.csv
done

# Figure 11: the collect best of seed 1 over 225 actions.
$B replay examples/khepera.bat --stage collect --run $R/khepera/seed-1 --actions 225 --seed 101 --out $R/figure11

for f in khepera/fitness-seeds scratch/fitness-seeds monolithic/fitness-seeds avoid-1/reinforcement \
  figure11/activations figure11/trajectory khepera/seed-1/bigger/reinforcement; do
  cp "$R/$f.png" "$D/$(echo "$f" | tr '/' '-').png"
done
for f in khepera scratch monolithic; do
  echo "== $f"
  cat $R/$f/summary.md
done
