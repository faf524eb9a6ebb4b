#!/usr/bin/env bash
# Set up brdfkit on a fresh machine: create .venv/ at the repository root and
# install brdfkit into it (editable). Idempotent: re-running only refreshes the
# installation.
#
#   bash scripts/setup.sh          # brdfkit and its runtime dependencies
#   bash scripts/setup.sh --test   # also the test extras (pytest, hypothesis, Mitsuba 3)
#   bash scripts/setup.sh --dev    # also the test extras and ruff
#
# Needs only Python >= 3.11 with pip (venv module). Environment: PYTHON selects
# the interpreter (default: python3).
set -euo pipefail

extra=""
for arg in "$@"; do
  case "$arg" in
    --test) extra="[test]" ;;
    --dev) extra="[dev]" ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$arg' (use --test, --dev or --help)" >&2; exit 2 ;;
  esac
done

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
py="${PYTHON:-python3}"

if ! "$py" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
  echo "setup.sh: brdfkit needs Python >= 3.11; '$py' is $("$py" --version 2>&1)" >&2
  exit 1
fi

if [ ! -x .venv/bin/python ]; then
  echo "setup.sh: creating .venv/ with $("$py" --version 2>&1)"
  "$py" -m venv .venv
fi

# System part: Mitsuba 3's llvm_* variants (rendering, the Mitsuba bridge and its tests) need
# Debian's libllvm19 (LLVM 15/16 load but abort on microfacet kernels). Installed with apt when
# running as root; otherwise brdfkit falls back to Mitsuba's scalar_* variants and says so.
if [ -n "$extra" ] || [ "${BRDFKIT_SYSTEM_DEPS:-0}" = 1 ]; then
  if ldconfig -p 2>/dev/null | grep -q 'libLLVM.so.19\|libLLVM-19'; then
    :
  elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "setup.sh: installing libllvm19 (apt) for Mitsuba's llvm_* variants"
    apt-get install -y -q libllvm19 >/dev/null 2>&1 \
      || { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q libllvm19 >/dev/null; } \
      || echo "setup.sh: warning: could not install libllvm19; Mitsuba renders fall back to scalar_* variants (slower)" >&2
  else
    echo "setup.sh: note: libllvm19 is missing and this is not root with apt-get; Mitsuba renders fall back to scalar_* variants (slower). Fix: sudo apt-get install libllvm19" >&2
  fi
fi

# System part for the explorer's browser tests (--test/--dev): Debian's chromium, driven by
# Playwright with executable_path (Playwright cannot download browsers here).
if [ -n "$extra" ]; then
  if command -v chromium >/dev/null 2>&1; then
    :
  elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "setup.sh: installing chromium (apt) for the explorer's browser tests"
    apt-get install -y -q chromium >/dev/null 2>&1 \
      || { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q chromium >/dev/null; } \
      || echo "setup.sh: warning: could not install chromium; the browser tests will be skipped (with this reason)" >&2
  else
    echo "setup.sh: note: chromium is missing and this is not root with apt-get; the explorer's browser tests will be skipped. Fix: sudo apt-get install chromium" >&2
  fi
fi

.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e ".${extra}"
.venv/bin/python -c "import brdfkit; print('setup.sh: brdfkit', brdfkit.__version__, 'ready in .venv/')"
