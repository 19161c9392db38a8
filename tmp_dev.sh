#!/usr/bin/env bash
# One device call (not kept): build this tree and HEAD's (tmp_old.tar), the CUDA filter on
# this tree, then the contact stage's bench old/new alternated.
set -uo pipefail
SRC=$(pwd)
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
mkdir -p /tmp/old && tar -xf tmp_old.tar -C /tmp/old
ARGS="$SOFTTLED_DEVICE_CMAKE_ARGS -DSOFTTLED_CUDA=ON -DSOFTTLED_BUILD_BENCH=OFF -DSOFTTLED_PYTHON=OFF -DSOFTTLED_RENDER=OFF -DCMAKE_BUILD_TYPE=Release"
t0=$(date +%s)
( cmake -S $SRC -B /tmp/bnew $ARGS >/dev/null && cmake --build /tmp/bnew -j10 ) > $OUT/build_new.log 2>&1 &
( cmake -S /tmp/old -B /tmp/bold $ARGS >/dev/null && cmake --build /tmp/bold -j6 --target softtled ) > $OUT/build_old.log 2>&1 &
wait
echo "built in $(( $(date +%s) - t0 )) s"; ls -la /tmp/bnew/softtled /tmp/bold/softtled || { tail -30 $OUT/build_new.log; tail -30 $OUT/build_old.log; exit 1; }
export SOFTTLED_CACHE_DIR=/tmp/cache
cd /tmp/bnew
OMP_NUM_THREADS=3 timeout 330 ctest -R "cuda|Cuda|Gpu|GPU|Bodies|BodyLaws|MeshObstacle|SelfContact|Obstacles|DeviceWatchdog|HaloBlocks|LiveChanges|BodyContact|ObstacleStart|VtuBodies|Extremes|FloatFar|Watchdog|Adaptive|EnvSetting|TetForces" -j5 > $OUT/ctest.log 2>&1
grep -E "tests passed|Failed|\(Failed\)|Timeout" $OUT/ctest.log | head -20
cd $SRC
S=assets/scenes/torus_stack.toml
FINE="body.0.segments=[91,19] body.1.segments=[91,19] body.2.segments=[91,19]"
for r in 1 2; do
  for b in old new; do
    x=$(/tmp/b$b/softtled bench --scene $S --backend cuda --no-compare --steps 8000 --set $FINE 2>&1 | grep -E "us/step|median" | head -2 | tr '\n' ' ')
    echo "fine8k $b r$r: $x"
    x=$(/tmp/b$b/softtled bench --scene $S --backend cuda --no-compare --steps 8000 2>&1 | grep -E "us/step|median" | head -2 | tr '\n' ' ')
    echo "coarse $b r$r: $x"
  done
done
for b in old new; do
  x=$(/tmp/b$b/softtled bench --scene $S --backend cuda --no-compare --steps 60000 --samples 3 --set $FINE 2>&1 | grep -E "us/step|median" | head -2 | tr '\n' ' ')
  echo "fine60k $b: $x"
done
for b in old new; do
  /tmp/b$b/softtled run --scene $S --backend cuda --csv $OUT/stack_$b.csv 2>&1 | tail -2
  /tmp/b$b/softtled run --scene $S --backend cpu --csv $OUT/stack_cpu_$b.csv --set solver.precision=float 2>&1 | tail -1
done
SOFTTLED_CUDA_GRAPH_STEPS=abc /tmp/bnew/softtled run --scene assets/scenes/torus_coarse.toml --backend cuda --set time.duration=0.001; echo "env rc $?"
