#!/usr/bin/env bash
# Installs whatever Spindle needs from Debian's packages. Idempotent, and silent when
# everything is already there. `setup.sh --test` adds what only `make test` needs.
set -euo pipefail

packages=(
  g++ cmake make pkg-config
  libeigen3-dev libhwloc-dev libtomlplusplus-dev
  libcli11-dev               # the spindle program's command line
  libcpp-httplib-dev libjs-three  # spindle view: its HTTP server, and three.js for its page
  libgtest-dev libgmock-dev libbenchmark-dev
  libtbb-dev libbullet-dev   # bench-only peers
  gnuplot-nox                # docs/accuracy.png
  python3                    # test helpers (JSON checks)
  clang-format clang-tidy    # make format / format-check (part of make test), make tidy
)
if [[ ${1:-} == --test ]]; then
  packages+=(chromium)       # the view page's test in a real (headless) browser
elif [[ $# -gt 0 ]]; then
  echo "setup: unknown argument '$1' (only --test: also install make test's packages)" >&2
  exit 2
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
((${#missing[@]} == 0)) && exit 0

echo "setup: installing ${missing[*]}"
sudo=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
