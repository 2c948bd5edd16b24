#!/usr/bin/env bash
# CI for the Python package (python/): build it with maturin through pip, then run its tests
# (the same answers as `stamp run`, which they run too; pyvista for the .vtu cross-checks,
# matplotlib for the README's example).
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m pip install --quiet --disable-pip-version-check maturin pytest numpy pyvista matplotlib
# the `stamp` program the tests compare against; the package's build shares its target folder
cargo build --release -p stamp-cli
export CARGO_TARGET_DIR="$PWD/target"
python3 -m pip install --quiet --disable-pip-version-check ./python
# from the repository's root: python/stamp (the sources) must not shadow the installed package
pytest -q python/tests
