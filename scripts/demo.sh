#!/usr/bin/env bash
# The main job on bundled data: installs what is missing, builds, registers the bundled
# affine-distorted pair and writes the overlay picture (overlay.png) and the scale-selection
# plot (plot.svg) into the current folder's build/ output.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/tools/amscr register examples/pair-source.png examples/pair-target.png \
  --overlay build/overlay.png --plot build/plot.svg "$@"
echo "pictures: build/overlay.png (target grey, source before dashed blue, after red), build/plot.svg"
