#!/usr/bin/env bash
# Configures and builds shelldyn in ./build (Release, 2 jobs). Executables land in build/bin/.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j2
