#!/usr/bin/env bash
# One-time set-up on a fresh Debian machine: system packages, a virtual environment,
# torch from the CPU wheel first, then the pinned stack. Safe to run again: it only does
# what is missing. Called by `make` before any target that needs the environment.
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=${VENV:-.venv}
PYTHON=${PYTHON:-$(command -v python3.11 || command -v python3)}
DEBS="libosmesa6 graphviz"   # off-screen MuJoCo rendering; `dot` draws automata

missing=()
for pkg in $DEBS; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "setup: installing Debian packages: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi

if [ ! -x "$VENV/bin/python" ]; then
  echo "setup: creating $VENV with $PYTHON"
  "$PYTHON" -m venv "$VENV"
fi
PIP="$VENV/bin/python -m pip --disable-pip-version-check -q"
# torch first: a CPU wheel lies on disk; anything that depends on torch and comes first
# would pull several GB of CUDA wheels instead.
$VENV/bin/python -c "import torch" 2>/dev/null || $PIP install "torch==2.13.0"
$PIP install -c constraints.txt -e ".[dev]"
echo "setup: done ($VENV)"
