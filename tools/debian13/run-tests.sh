#!/usr/bin/env bash
# The test suite on Debian 13 (trixie: dolfinx 0.9, PETSc/SLEPc 3.22, mpi4py 4, NumPy 2,
# Python 3.13), in a chroot built with debootstrap from the host's own Debian mirror.
#
#   tools/debian13/run-tests.sh          # build .debian13/ once (a few minutes), then `make test`
#   tools/debian13/run-tests.sh demo     # any make targets instead of `test`
#   DEBIAN13_ROOT=/path tools/debian13/run-tests.sh
#
# The chroot is kept and reused; its packages are those of the Makefile's set-up, installed by
# the project's own `make setup` inside it. The checkout is bind-mounted at /src, and the
# chroot's own `make test` (lint, serial, mpirun -n 2) runs there with its own venv
# (.venv-debian13, so the host's .venv is left alone). Needs root (debootstrap, mount, chroot).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
root=${DEBIAN13_ROOT:-$here/.debian13}
suite=trixie
sudo=$([ "$(id -u)" = 0 ] || echo sudo)

# the host's Debian mirror (deb822 or one-line sources), not a hard-coded one
mirror=$(sed -n 's/^URIs:[[:space:]]*\([^[:space:]]*\/debian\)\/*$/\1/p' \
             /etc/apt/sources.list.d/*.sources 2>/dev/null | head -n 1)
if [ -z "$mirror" ]; then
    mirror=$(awk '$1 == "deb" && $2 ~ /\/debian\/?$/ {print $2; exit}' \
                 /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null || true)
fi
[ -n "$mirror" ] || { echo "debian13: no Debian mirror found in the host's apt sources" >&2; exit 2; }

if ! command -v debootstrap > /dev/null; then
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends debootstrap
fi

if [ ! -e "$root/.debootstrap-done" ]; then
    echo "debian13: building the $suite chroot in $root from $mirror"
    $sudo rm -rf "$root"
    start=$(date +%s)
    $sudo debootstrap --variant=minbase --include=make,ca-certificates "$suite" "$root" "$mirror"
    echo "deb $mirror $suite main" | $sudo tee "$root/etc/apt/sources.list" > /dev/null
    $sudo touch "$root/.debootstrap-done"
    echo "debian13: chroot built in $(( $(date +%s) - start )) s"
fi

mounts=(proc sys dev dev/pts dev/shm src)
cleanup() {
    for (( i=${#mounts[@]}-1; i>=0; i-- )); do
        mountpoint -q "$root/${mounts[i]}" && $sudo umount -l "$root/${mounts[i]}" || true
    done
}
trap cleanup EXIT
$sudo mkdir -p "$root/src"
$sudo mount -t proc proc "$root/proc"
$sudo mount --rbind /sys "$root/sys"
$sudo mount --bind /dev "$root/dev"
$sudo mount --bind /dev/pts "$root/dev/pts"
$sudo mount -t tmpfs tmpfs "$root/dev/shm"
$sudo mount --bind "$here" "$root/src"
$sudo cp /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null || true
# the host's certificate authorities (pip reaches PyPI over TLS for the linters; a site may
# add its own authority to the host's bundle)
$sudo mkdir -p "$root/etc/ssl/certs"
$sudo cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/host-ca-certificates.crt"

# `make setup` installs the Debian packages (apt-get update first) and the venv, as on a fresh
# machine; VENV keeps the chroot's venv apart from the host's
$sudo chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LANG=C.UTF-8 \
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
    PIP_CERT=/etc/ssl/certs/host-ca-certificates.crt \
    bash -c "cd /src && make VENV=.venv-debian13 ${*:-test}"
