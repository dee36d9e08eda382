#!/usr/bin/env bash
# Regenerates every number and picture of EXPERIMENTS.md (about 50 minutes
# of CPU time: measured at e957a7e, 49 minutes, 47 on two cores shared with
# other work). Results go to runs/experiments/; the pictures EXPERIMENTS.md
# shows are copied next to this script; the numbers are printed.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
T=${CARGO_TARGET_DIR:-target}/release
B=$T/shaping
L=$T/examples/lives
R=runs/experiments
D=docs/experiments
SEEDS=10
mkdir -p "$R"

# Figures 4, 9 and 13: every stage of khepera.bat over seeds 1..10.
$B experiment examples/khepera.bat --seeds $SEEDS --out $R/khepera --fresh \
  --criterion navigation=0.7 --criterion collect=3 > /dev/null
# The other choice for learning during evolution (navigation only).
$B experiment examples/pretrained.bat --seeds $SEEDS --out $R/pretrained --fresh --criterion navigation=0.7 > /dev/null
# The paper's fitness against one that counts forward motion only.
sed 's#fitness per action abs(wheels\[0\] + wheels\[1\]) / 2#fitness per action max(wheels[0] + wheels[1], 0) / 2#' \
  examples/pretrained.bat > $R/forward-only.bat
grep -q 'max(wheels\[0\] + wheels\[1\], 0)' $R/forward-only.bat
$B experiment $R/forward-only.bat --seeds $SEEDS --out $R/forward-only --fresh --criterion navigation=0.7 > /dev/null
# The exploring variant (EXPERIMENTS.md, "An avoid module that turns"):
# khepera.bat with four changes, each checked: the avoid module's fourth
# motion turns instead of backing; navigation evolves 100 generations on 3
# episodes per individual; collect evolves 80 generations, Lamarckian; grip
# and release learn at CRBP's default rates.
sed -e 's#outputs sign(2) -> forward | right | left | back#outputs sign(2) -> forward | right | left | right#' \
  -e 's#evolve { population 100  generations 40  actions 300  seed 1  mutation 0.02 }#evolve { population 100  generations 100  actions 300  seed 1  mutation 0.02  evaluations 3 }#' \
  -e 's#evolve { generations 40 }#evolve { generations 80  inheritance lamarckian }#' \
  -e 's#learn crbp(1, 0.5) on activation always#learn crbp(0.5, 0.1) on activation always#' \
  examples/khepera.bat > $R/khepera-explore.bat
[ "$(grep -c 'forward | right | left | right' $R/khepera-explore.bat)" = 2 ]
grep -q 'generations 100  actions 300  seed 1  mutation 0.02  evaluations 3' $R/khepera-explore.bat
grep -q 'generations 80  inheritance lamarckian' $R/khepera-explore.bat
[ "$(grep -c 'learn crbp(0.5, 0.1) on activation always' $R/khepera-explore.bat)" = 2 ]
$B experiment $R/khepera-explore.bat --seeds $SEEDS --out $R/khepera-explore --fresh \
  --criterion navigation=0.7 --criterion collect=3 > /dev/null
# examples/khepera-practice.bat: the exploring variant with grip and
# release trained before evolution (the paper's figure 8), and figure 13's
# test (bigger) with its two controls (bigger_nolearning, bigger_unchanged),
# each 40 lives before and 40 after the change, the same lives in all three.
# Its avoidance and navigation stages are the variant's: resumed from the
# variant's runs (the checkpoints say they are done, and the files are
# those a fresh run writes), not evolved again.
rm -rf $R/khepera-practice
for s in $(seq 1 $SEEDS); do
  mkdir -p $R/khepera-practice/seed-$s
  cp -r $R/khepera-explore/seed-$s/avoidance $R/khepera-explore/seed-$s/navigation $R/khepera-practice/seed-$s/
done
$B experiment examples/khepera-practice.bat --seeds $SEEDS --out $R/khepera-practice \
  --criterion navigation=0.7 --criterion collect=3 > /dev/null
# The level the same architecture reaches with 25 mm objects from the
# start: khepera-practice.bat with 25 mm objects in its training stage and
# in collect (the variant's avoidance and navigation reused); its test
# `bigger` then keeps 25 mm objects, and `bigger_unchanged` takes them from
# 25 to 10 mm: the same individuals on both sides.
sed -e 's#objects 8 diameter 10mm virtual#objects 8 diameter 25mm virtual#' \
  examples/khepera-practice.bat > $R/f13-at25.bat
[ "$(grep -c 'objects 8 diameter 25mm virtual' $R/f13-at25.bat)" = 2 ]
rm -rf $R/f13-at25
for s in $(seq 1 $SEEDS); do
  mkdir -p $R/f13-at25/seed-$s
  cp -r $R/khepera-explore/seed-$s/avoidance $R/khepera-explore/seed-$s/navigation $R/f13-at25/seed-$s/
done
$B experiment $R/f13-at25.bat --seeds $SEEDS --out $R/f13-at25 --criterion collect=3 > /dev/null
# Shaping against evolution from scratch on the whole task.
$B experiment examples/scratch-full.bat --seeds $SEEDS --out $R/scratch-full --fresh --criterion full=3 > /dev/null

# The mutation rate (EXPERIMENTS.md, "Settings that differ from the paper"):
# khepera.bat's navigation over seeds 1..10 at each rate tried in development.
$B experiment examples/khepera.bat --stage navigation --seeds $SEEDS --out $R/mutation --fresh --no-report \
  --set navigation.evolve.mutation=0.01,0.02,0.03,0.05 --criterion navigation=0.7 > /dev/null

# Floreano & Mondada 1994 (obstacle avoidance) and 1996 (homing for
# battery recharge), both evolved from scratch; the 1996 one against
# khepera.bat's navigation is the paper's "almost one order of magnitude".
$B experiment examples/floreano-mondada-1994.bat --seeds $SEEDS --out $R/fm1994 --fresh > /dev/null
$B experiment examples/floreano-mondada-1996.bat --seeds $SEEDS --out $R/fm1996 --fresh > /dev/null
# The charger example of docs/language.md (section 18), verbatim: does its
# best farm recharges? (the code block that declares `1 per recharge`)
python3 - > $R/charger.bat <<'PY'
import re
text = open("docs/language.md").read()
blocks = re.findall(r"```bat\n(.*?)```", text, re.S)
print(next(b for b in blocks if "1 per recharge" in b), end="")
PY
grep -q 'uses charger' $R/charger.bat
$B experiment $R/charger.bat --seeds $SEEDS --out $R/charger --fresh > /dev/null
# The cue-then-choose T-maze: the cue read in a start box, then the robot
# placed at the foot of the stem; the recurrent network (t-maze.bat) and
# the feed-forward control (the same file without the context), each best
# tested on 100 fresh lives in the task's two variants, and the test
# between them (printed).
sed 's#hidden 6 recurrent  outputs#hidden 6  outputs#' examples/t-maze.bat > $R/t-maze-ff.bat
grep -q 'behavior neural { hidden 6  outputs linear' $R/t-maze-ff.bat
[ "$(grep -c 'recurrent  outputs' $R/t-maze-ff.bat)" = 0 ]
$B experiment examples/t-maze.bat --seeds $SEEDS --out $R/t-maze --fresh > /dev/null
$B experiment $R/t-maze-ff.bat --seeds $SEEDS --out $R/t-maze-ff --fresh > /dev/null
$B compare $R/t-maze $R/t-maze-ff --stage maze_test
# A team shaped stage by stage (shaped-team.bat: role `scout` learns to
# explore, then adds modules to recharge; then role `guard`, whose fitness
# is to keep the team together, joins it) against the same final
# architecture evolved from generation 0 for the same 9,600 evaluations
# (shaped-team-scratch.bat). The criterion, stated before seeds 1 to 10
# ran: escort's best >= 0.43. The tests (printed): the final test `check`,
# and escort within its own generations; analyse.py counts the evaluations
# to the criterion with the shaped file's earlier stages.
$B experiment examples/shaped-team.bat --seeds $SEEDS --out $R/shaped-team --fresh --criterion escort=0.43 > /dev/null
$B experiment examples/shaped-team-scratch.bat --seeds $SEEDS --out $R/shaped-team-scratch --fresh \
  --criterion escort=0.43 > /dev/null
$B compare $R/shaped-team $R/shaped-team-scratch --stage check
$B compare $R/shaped-team $R/shaped-team-scratch --stage escort --criterion escort=0.43

# When shaping pays (EXPERIMENTS.md, "a ladder of batteries", stated before
# it ran): khepera.bat against scratch-full.bat (its stage renamed
# `collect`) with the battery at 200, 120 and 80 actions, both ending with
# the same test `exam`. Printed: per rung, the tests of the evaluations to
# a best of 3.0 (the whole path) and of exam's fitness.
for b in 200 120 80; do
  exam='stage exam extends collect {\n  test best for 20 lives of 300 actions with learning\n}\n'
  sed -e "s#battery 200 actions, recharge 20 actions#battery $b actions, recharge 20 actions#" \
    examples/khepera.bat > $R/ladder-$b-shaped.bat
  sed -e "s#battery 200 actions, recharge 20 actions#battery $b actions, recharge 20 actions#" \
    -e 's#^stage full {#stage collect {#' examples/scratch-full.bat > $R/ladder-$b-scratch.bat
  for f in shaped scratch; do
    printf "\n$exam" >> $R/ladder-$b-$f.bat
    [ "$(grep -c "battery $b actions, recharge 20 actions" $R/ladder-$b-$f.bat)" = 1 ]
    [ "$(grep -c '^stage collect\|^stage exam extends collect {' $R/ladder-$b-$f.bat)" = 2 ]
    $B experiment $R/ladder-$b-$f.bat --seeds $SEEDS --out $R/ladder-$b-$f --fresh --no-report \
      --criterion collect=3 > /dev/null
  done
  echo "== ladder: battery $b actions"
  $B compare $R/ladder-$b-shaped $R/ladder-$b-scratch --stage collect --criterion collect=3 \
    | grep -E 'reaching criterion|^Groups'
  $B compare $R/ladder-$b-shaped $R/ladder-$b-scratch --stage exam | grep -E '\| exam \| fitness'
done

# Teams (EXPERIMENTS.md, "Teams: aggregation and cooperative collect"):
# aggregation.bat's 10 robots, and team-collect.bat's 4 robots with 16
# objects against one robot with 4 objects in khepera.bat's arena (the same
# file with three changes, each checked).
$B experiment examples/aggregation.bat --seeds $SEEDS --out $R/aggregation --fresh > /dev/null
$B experiment examples/aggregation-roles.bat --seeds $SEEDS --out $R/aggregation-roles --fresh > /dev/null
# The same task with the range-and-bearing board (aggregation-rab.bat), the
# same budget.
$B experiment examples/aggregation-rab.bat --seeds $SEEDS --out $R/aggregation-rab --fresh > /dev/null
# Foraging with recruitment (recruit.bat, EXPERIMENTS.md "Recruitment"):
# its tests with signals and with every broadcast heard as 0 (the ablation,
# same lives), and a team evolved without the broadcast (the `heard`
# sensor, the actuator, the network's broadcast and the silent test removed).
$B experiment examples/recruit.bat --seeds $SEEDS --out $R/recruit --fresh > /dev/null
sed -e '/sensor heard\[8\] *signal/d' -e '/actuator signal *broadcast/d' -e 's/, heard//' \
  -e 's/  broadcast signal//' -e '/^\/\/ The same lives with every broadcast/,$d' examples/recruit.bat > $R/recruit-mute.bat
[ "$(grep -v '^//' $R/recruit-mute.bat | grep -c 'signal$\|broadcast$\|broadcast signal \|heard\|rab_signals')" = 0 ]
grep -q 'toward(rab) }' $R/recruit-mute.bat
$B experiment $R/recruit-mute.bat --seeds $SEEDS --out $R/recruit-mute --fresh > /dev/null
$B compare $R/recruit $R/recruit-mute --stage forage_test | grep -E '\| forage_test \| fitness'
cargo run --release --quiet --example ablation -- $R/recruit forage_silent
# What the signal means: broadcasts on and off the food, hearing, approach.
python3 $D/recruit_meaning.py $R/recruit
# Twice the generations for the clones and the roles: does the roles'
# longer genome catch up?
for f in aggregation aggregation-roles; do
  sed 's/generations 60 /generations 120 /' examples/$f.bat > $R/$f-120.bat
  grep -q 'generations 120 ' $R/$f-120.bat
  $B experiment $R/$f-120.bat --seeds $SEEDS --out $R/$f-120 --fresh > /dev/null
done
$B experiment examples/team-collect.bat --seeds $SEEDS --out $R/team-collect --fresh > /dev/null
sed -e 's#arena 800mm x 1200mm#arena 400mm x 600mm#' -e 's#charger 400mm on north wall#charger 200mm on north wall#' \
  -e '/^    robots 4$/d' -e 's#/ 300, team sum$#/ 300#' -e 's#objects 16 diameter#objects 4 diameter#' \
  examples/team-collect.bat > $R/team-collect-solo.bat
grep -q 'arena 400mm x 600mm' $R/team-collect-solo.bat
grep -q 'charger 200mm on north wall' $R/team-collect-solo.bat
grep -q 'objects 4 diameter 10mm' $R/team-collect-solo.bat
[ "$(grep -c '^    robots \|, team sum' $R/team-collect-solo.bat)" = 0 ]
$B experiment $R/team-collect-solo.bat --seeds $SEEDS --out $R/team-collect-solo --fresh > /dev/null
# One robot in the team's world (its arena, charger and 16 objects): what
# the arena does, without the other robots.
sed -e '/^    robots 4$/d' -e 's#/ 300, team sum$#/ 300#' examples/team-collect.bat > $R/team-collect-one.bat
[ "$(grep -c '^    robots \|, team sum' $R/team-collect-one.bat)" = 0 ]
$B experiment $R/team-collect-one.bat --seeds $SEEDS --out $R/team-collect-one --fresh > /dev/null

# The chosen bests at work: three fresh episodes each (seeds 101..103),
# with learning and, for collect, without it (how much grip decisions owe
# to learning within the life).
: > $R/replays.txt
for s in $(seq 1 $SEEDS); do
  for r in 101 102 103; do
    for spec in "khepera navigation" "khepera collect" "khepera-explore navigation" "khepera-explore collect" \
      "khepera-practice navigation" "khepera-practice collect" "pretrained navigation" "forward-only navigation" "scratch-full full" \
      "team-collect collect" "team-collect-solo collect" "team-collect-one collect"; do
      set -- $spec
      file=examples/$1.bat; [ -f "$file" ] || file=$R/$1.bat
      echo "$1 $2 $s $r learning $($B replay $file --stage $2 --run $R/$1/seed-$s --seed $r --out $R/replay-$1-$2-$s-$r | sed 's/ -> .*//')" >> $R/replays.txt
    done
    for f in khepera khepera-explore khepera-practice; do
      file=examples/$f.bat; [ -f "$file" ] || file=$R/$f.bat
      echo "$f collect $s $r nolearning $($B replay $file --stage collect --run $R/$f/seed-$s --seed $r --no-learning --out $R/replay-$f-collect-nl-$s-$r | sed 's/ -> .*//')" >> $R/replays.txt
    done
  done
done

# Figure 5: avoid.bat over seeds 1..10 (one training life of 1000 actions each).
for s in $(seq 1 $SEEDS); do
  $B run examples/avoid.bat --seed $s --out $R/avoid-$s --fresh --quiet
done

# Figure 11: the collect best of seed 1 over 225 actions, as pictures and
# as an animation.
$B replay examples/khepera.bat --stage collect --run $R/khepera/seed-1 --actions 225 --seed 101 --out $R/figure11 --gif $D/figure11.gif > /dev/null
$B replay examples/khepera-practice.bat --stage collect --run $R/khepera-practice/seed-1 --actions 225 --seed 101 --out $R/practice-figure11 --gif $D/practice-figure11.gif > /dev/null

# The teams' bests of seed 1 in episode 101, for the pictures.
$B replay examples/aggregation.bat --stage aggregate --run $R/aggregation/seed-1 --seed 101 --out $R/aggregation-replay > /dev/null
$B replay examples/team-collect.bat --stage collect --run $R/team-collect/seed-1 --seed 101 --out $R/team-collect-replay > /dev/null

# The F&M 1996 best of seed 1 over its 150 actions, for the picture.
$B replay examples/floreano-mondada-1996.bat --stage homing --run $R/fm1996/seed-1 --seed 101 --out $R/fm1996-replay > /dev/null

for f in khepera/fitness-seeds scratch-full/fitness-seeds avoid-1/avoid/reinforcement fm1996/fitness-seeds fm1996-replay/trajectory \
  figure11/activations figure11/trajectory \
  khepera-practice/fitness-seeds practice-figure11/activations practice-figure11/trajectory \
  khepera-practice/seed-1/bigger/reinforcement aggregation-replay/trajectory team-collect-replay/trajectory \
  shaped-team/seed-1/check/trajectory shaped-team-scratch/seed-1/check/trajectory \
  ladder-80-shaped/fitness-seeds ladder-80-scratch/fitness-seeds; do
  cp "$R/$f.png" "$D/$(echo "$f" | tr '/' '-').png"
done

# The teams in 20 fresh lives per seed, the same lives for every team, and
# 100 lives of random walkers, the first one drawn (docs/experiments/walkers.rs).
cargo build --release --quiet --example walkers
$T/examples/walkers examples/aggregation.bat --lives 100 --picture $D/aggregation-walkers.png > $R/walkers.txt
$T/examples/walkers examples/aggregation.bat --lives 20 --run $R/aggregation --seeds $SEEDS > $R/aggregation-lives.txt
$T/examples/walkers examples/aggregation-roles.bat --lives 20 --run $R/aggregation-roles --seeds $SEEDS \
  > $R/aggregation-roles-lives.txt
$T/examples/walkers examples/aggregation-rab.bat --lives 20 --run $R/aggregation-rab --seeds $SEEDS \
  > $R/aggregation-rab-lives.txt
for b in 200 120 80; do
  for f in shaped scratch; do
    $T/examples/walkers $R/ladder-$b-$f.bat --stage collect --lives 20 --run $R/ladder-$b-$f --seeds $SEEDS \
      > $R/ladder-$b-$f-lives.txt
  done
done
for f in aggregation aggregation-roles; do
  $T/examples/walkers $R/$f-120.bat --lives 20 --run $R/$f-120 --seeds $SEEDS > $R/$f-120-lives.txt
done
$T/examples/walkers examples/team-collect.bat --stage collect --lives 20 --run $R/team-collect --seeds $SEEDS \
  > $R/team-collect-lives.txt
$T/examples/walkers $R/team-collect-solo.bat --stage collect --lives 20 --run $R/team-collect-solo --seeds $SEEDS \
  > $R/team-collect-solo-lives.txt
$T/examples/walkers $R/team-collect-one.bat --stage collect --lives 20 --run $R/team-collect-one --seeds $SEEDS \
  > $R/team-collect-one-lives.txt

# What the world allows in the collect stage: a blind search with perfect
# gripping, releasing and recharging, and each seed's collect best with
# perfect grip and release decisions (docs/experiments/oracle.rs).
cargo build --release --quiet --example oracle
$T/examples/oracle examples/khepera.bat --run $R/khepera > $R/oracle.txt
$T/examples/oracle $R/khepera-explore.bat --run $R/khepera-explore > $R/oracle-explore.txt

# What the proximity sensors allow the grip and release decisions
# (docs/experiments/discriminate.rs): rules fitted on the exploring
# variant's lives (linear as its activation networks, with 4 hidden units,
# quadratic) decide in the lives of the other half of the seeds; and how
# well the real Khepera's readings tell a wall from a 25 mm cylinder.
cargo build --release --quiet --example discriminate
$T/examples/discriminate $R/khepera-explore.bat --run $R/khepera-explore > $R/discriminate.txt

# The grip script's mechanics alone (docs/experiments/grip.rs): the share of
# objects it catches when started in front of one, with the four turns that
# face the object and without them (the script before this report).
cargo build --release --quiet --example grip
$T/examples/grip examples/khepera.bat > $R/grip.txt
grep -v -E '^      turn (left|right)\((0.5|0.25)\) if ' examples/khepera.bat > $R/khepera-no-facing.bat
[ "$(grep -c 'turn left(0.5) if' $R/khepera-no-facing.bat)" = 0 ]
$T/examples/grip $R/khepera-no-facing.bat > $R/grip-no-facing.txt
$T/examples/grip examples/khepera.bat --diameter 25 > $R/grip-25mm.txt

# What learning in the test does, and whether the architecture holds a grip
# network that copes with 25 mm objects (docs/experiments/lives.rs):
# khepera-practice's collect bests in the 40 + 40 lives of its tests,
# (a) with grip and release networks trained by the practice stage with
# 25 mm objects instead of 10 mm (the same evolved links), and (b) with the
# test learning at CRBP 0.5 / 0.25 and 0.5 / 0.5 instead of collect's
# 0.5 / 0.1. The tests' own lives (which the tool reproduces) are the
# reference.
cargo build --release --quiet --example lives
sed 's#objects 8 diameter 10mm virtual }  // as in collect#objects 8 diameter 25mm virtual }  // as in collect#' \
  examples/khepera-practice.bat > $R/lives-practice25.bat
grep -q 'objects 8 diameter 25mm virtual }  // as in collect' $R/lives-practice25.bat
[ "$(grep -c 'diameter 10mm virtual' $R/lives-practice25.bat)" = 1 ]
for r in 0.25 0.5; do
  sed "s#^    learn crbp(0.5, 0.1) on activation always\$#    learn crbp(0.5, $r) on activation always#" \
    examples/khepera-practice.bat > $R/lives-$r.bat
  [ "$(grep -c '^    learn crbp(0.5, 0.1) on activation always$' examples/khepera-practice.bat)" = 2 ]
  [ "$(grep -c '^    learn crbp(0.5, 0.1) on activation always$' $R/lives-$r.bat)" = 0 ]
done
for v in bigger bigger_unchanged bigger_nolearning; do
  $L examples/khepera-practice.bat --stage $v --run $R/khepera-practice > $R/lives-$v.txt
  $L $R/lives-practice25.bat --stage $v --run $R/khepera-practice > $R/lives-$v-practice25.txt
done
for v in bigger bigger_unchanged; do
  for r in 0.25 0.5; do
    $L $R/lives-$r.bat --stage $v --run $R/khepera-practice > $R/lives-$v-$r.txt
  done
done

for f in khepera khepera-explore khepera-practice pretrained forward-only scratch-full mutation; do
  echo "== $f"
  cat $R/$f/summary.md
done
python3 docs/experiments/analyse.py "$R" "$SEEDS"
echo "== the ceiling of the collect stage (oracle)"
grep -E '^(search|decisions|evolved|physical) (random|even): ' $R/oracle.txt
grep '^decisions random, ' $R/oracle.txt
echo "== the grip script alone, with the turns that face the object, then without them"
tail -5 $R/grip.txt
tail -5 $R/grip-no-facing.txt
echo "== the same script with stage bigger's 25 mm objects"
tail -5 $R/grip-25mm.txt
echo "== the same for the exploring variant"
grep -E '^(decisions|evolved|physical) (random|even): ' $R/oracle-explore.txt
grep '^decisions random, ' $R/oracle-explore.txt
echo "== what the proximity sensors allow the decisions (exploring variant)"
cat $R/discriminate.txt

echo "== teams: aggregation (random walkers, then the evolved teams)"
tail -1 $R/walkers.txt
grep -E '^seed [0-9]+ \(' $R/aggregation-lives.txt
grep -A5 '^over the seeds' $R/aggregation-lives.txt
echo "== teams: aggregation by two roles of 5 robots"
grep -E '^seed [0-9]+ \(' $R/aggregation-roles-lives.txt
grep -A5 '^over the seeds' $R/aggregation-roles-lives.txt
echo "== teams: aggregation with the range-and-bearing board (aggregation-rab.bat)"
grep -E '^seed [0-9]+ \(' $R/aggregation-rab-lives.txt
grep -A5 '^over the seeds' $R/aggregation-rab-lives.txt
$B compare $R/aggregation $R/aggregation-rab --stage aggregate | grep -E '\| chosen best \|'
echo "== teams: aggregation with 120 generations, the clones then the roles"
grep -A1 '^over the seeds' $R/aggregation-120-lives.txt
grep -A1 '^over the seeds' $R/aggregation-roles-120-lives.txt
echo "== teams: cooperative collect, 4 robots and 16 objects, then 1 robot and 4 objects"
grep -E '^seed [0-9]+ \(' $R/team-collect-lives.txt
grep -A5 '^over the seeds' $R/team-collect-lives.txt
grep -E '^seed [0-9]+ \(' $R/team-collect-solo-lives.txt
grep -A5 '^over the seeds' $R/team-collect-solo-lives.txt
echo "== teams: cooperative collect, 1 robot in the team's world (800 x 1200 mm, 16 objects)"
grep -E '^seed [0-9]+ \(' $R/team-collect-one-lives.txt
grep -A5 '^over the seeds' $R/team-collect-one-lives.txt
echo "== the same in the replays (3 per seed): recharges and actions per life"
for f in team-collect team-collect-solo team-collect-one; do
  grep "^$f collect " $R/replays.txt | awk -v f=$f '{ n++; a += $7; for (i = 1; i < NF; i++) if ($(i+1) == "recharges,") r += $i }
    END { printf "%s: %d recharges in %d lives, %.1f actions per life\n", f, r, n, a / n }'
done

# Speed: one seed of the whole khepera.bat (median of 3), and the benchmark.
times=""
for i in 1 2 3; do
  t0=$(date +%s.%N)
  $B run examples/khepera.bat --fresh --quiet --no-report --out $R/speed > /dev/null
  t1=$(date +%s.%N)
  times="$times $(echo "$t1 - $t0" | bc -l)"
done
echo "== speed"
python3 -c 'import sys, statistics as st; t = sorted(map(float, sys.argv[1:])); print("one seed of khepera.bat: median %.2f s, runs %s" % (st.median(t), " ".join("%.2f" % x for x in t)))' $times
$B bench examples/khepera.bat --stage navigation
$B bench examples/khepera.bat --stage collect
