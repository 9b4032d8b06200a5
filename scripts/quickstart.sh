#!/usr/bin/env bash
# Quick start, step 1 of 2: install the Debian packages, build, and run the main job.
# The main job is the flying L-shaped plate benchmark (FLP-prov); its results are written to
# results/flying-plate/ and summarised on the terminal.
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=1
bash scripts/install-deps.sh
bash scripts/build.sh
echo
echo "=== main job: build/bin/shelldyn check apps/cases/flying-plate.yaml -o results/flying-plate"
build/bin/shelldyn check apps/cases/flying-plate.yaml -o results/flying-plate
