#!/usr/bin/env bash
# Quick start, step 1 of 2: install the Debian packages, build, and run the main job.
# The main job integrates the flying L-shaped plate benchmark (FLP-prov) with the paper's scheme through
# its load phase and one second of free flight; results go to results/flying-plate/em-galpha/
# (history.csv, fields.pvd + VTU, run.json) and a summary is printed.
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=1
bash scripts/install-deps.sh
bash scripts/build.sh
echo
echo "=== main job: the flying L-shaped plate (FLP-prov), em-galpha, loads on until t = 5 s, free flight to t = 6 s"
build/bin/shelldyn run apps/cases/flying-plate.yaml --t-end 6 -o results/flying-plate/em-galpha --overwrite
