#!/usr/bin/env bash
# Set up a fresh machine: a virtual environment in .venv with this project, its test
# tools and the other FMI engines it is tested in, and every FMU built into fmus/ (FMI 2.0)
# and its FMI 3.0 twin into fmus/fmi3/.
set -euo pipefail
cd "$(dirname "$0")"
python=${PYTHON:-python3}

# ecos (ecospy) links Debian's libtbb12.
if ! ldconfig -p 2>/dev/null | grep -q 'libtbb\.so\.12'; then
    if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
        apt-get install -y -q libtbb12 >/dev/null || { apt-get update -q >/dev/null && apt-get install -y -q libtbb12 >/dev/null; } \
            || echo "setup: could not install libtbb12; the ecos tests will be skipped" >&2
    else
        echo "setup: libtbb12 is missing (sudo apt-get install libtbb12); the ecos tests will be skipped" >&2
    fi
fi

"$python" -m venv .venv
.venv/bin/python -m pip install --quiet --disable-pip-version-check -e ".[test,engines]"
# ecospy ships its helper programs without the execute bit.
chmod +x .venv/lib/python*/site-packages/ecospy/binaries/ecos \
         .venv/lib/python*/site-packages/ecospy/binaries/proxyfmu 2>/dev/null || true
.venv/bin/python -m fmukit.build
.venv/bin/python -m fmukit.build --fmi 3
