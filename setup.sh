#!/usr/bin/env bash
# Set up a fresh machine: a virtual environment in .venv with this project and its
# test tools installed, and every FMU built into fmus/.
set -euo pipefail
cd "$(dirname "$0")"
python=${PYTHON:-python3}
"$python" -m venv .venv
.venv/bin/python -m pip install --quiet --disable-pip-version-check -e ".[test]"
.venv/bin/python -m fmukit.build
