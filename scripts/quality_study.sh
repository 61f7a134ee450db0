#!/usr/bin/env bash
# The study of docs/QUALITY.md (issue 18): does the Ferrari-Canny epsilon predict a simulated
# hold? Every grasp of the bundled scenarios, the tuning set and the real-object set.
#
#     scripts/quality_study.sh [OUT_DIR]        # default docs/quality
#
# Writes OUT_DIR/quality_study.csv, quality_study.md and quality_epsilon_payload.svg (see
# examples/quality_study.rs). About 20 minutes on the project's 2 cores when they are shared.
#
# - bundled scenarios and tuning set: up to 4 candidates per object, gravity `down` and `six`,
#   payload margin;
# - real-object set: up to 3 candidates per object, gravity `down` only, payload margin (`six`
#   on them too would double the run's length);
# - left out: libero_black_book (33 shells: its search runs 4 to 10 minutes before the fingertip
#   pinch finds its grasp, docs/REAL_OBJECTS.md).
#
# The real-object meshes that are not committed (their licence) are written by
# scripts/real_objects.py when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-docs/quality}

missing=0
for s in assets/real/scenarios/*.toml; do
  mesh=$(sed -n 's/^mesh *= *"\(.*\)".*/\1/p' "$s" | head -n 1)
  [ -f "assets/real/scenarios/$mesh" ] || missing=$((missing + 1))
done
if [ "$missing" -gt 0 ]; then
  echo "quality_study: $missing real-object meshes missing; running scripts/real_objects.py" >&2
  python3 scripts/real_objects.py >/dev/null
fi

real=()
for s in assets/real/scenarios/*.toml; do
  [ "$(basename "$s")" = libero_black_book.toml ] || real+=("$s")
done

cargo build --release --quiet --example quality_study
time target/release/examples/quality_study "$out" \
  --candidates 4 --gravity both scenarios/*.toml assets/objects/train/*.toml \
  --candidates 3 --gravity down "${real[@]}"
