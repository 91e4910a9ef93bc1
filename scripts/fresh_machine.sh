#!/usr/bin/env bash
# README's two commands on a fresh Debian machine, timed: a minimal Debian 12 root (debootstrap
# minbase, with only gcc, git and CA certificates added, as a machine set up for Rust has them), this
# machine's Rust toolchain mounted in read-only, an empty cargo home, a fresh clone of HEAD with
# ../shared beside it (read-only). Then, as root in the chroot (where the xtask may apt-get):
#
#   demo   cargo xtask demo      (prints DEMO rc=… wall=… s)
#   ci     bash .ci/run          (fmt, clippy, the runtime alone, cargo xtask test; CI rc=… wall=… s)
#
#   sudo scripts/fresh_machine.sh demo ci      # both, in that order, each on a fresh clone
#
# The root is made once in ROOT (default /var/tmp/terramp-fresh) and reused: remove it for a machine
# that has not seen an earlier run's packages and crates. Needs root, debootstrap and the network
# (Debian's mirror, crates.io, PyPI). CA certificates this machine adds under
# /usr/local/share/ca-certificates (a proxy's) are added to the root too.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
root="${ROOT:-/var/tmp/terramp-fresh}"
shared="$(cd "$repo/../shared" 2>/dev/null && pwd || true)"
[[ $(id -u) == 0 ]] || { echo "fresh_machine.sh: run as root (debootstrap, mount, chroot)" >&2; exit 1; }
[[ $# -gt 0 ]] || { echo "usage: fresh_machine.sh demo|ci ..." >&2; exit 2; }
toolchain="$(dirname "$(dirname "$(rustup which rustc)")")"
rustup_home="$(rustup show home)"

if [[ ! -x "$root/bin/bash" ]]; then
    command -v debootstrap >/dev/null || { echo "fresh_machine.sh: apt-get install debootstrap" >&2; exit 1; }
    debootstrap --variant=minbase --include=ca-certificates,git,gcc,libc6-dev bookworm "$root" \
        http://deb.debian.org/debian
fi
cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/" 2>/dev/null || true
cp /etc/resolv.conf "$root/etc/resolv.conf"

bind() { # bind SOURCE TARGET [ro]
    mkdir -p "$2"
    mountpoint -q "$2" && return
    mount --bind "$1" "$2"
    [[ ${3:-} == ro ]] && mount -o remount,bind,ro "$2"
    mounted+=("$2")
}
mounted=()
trap 'for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[i]}"; done' EXIT
bind /proc "$root/proc"
bind /sys "$root/sys"
mkdir -p "$root/dev" && mountpoint -q "$root/dev" || { mount --rbind /dev "$root/dev"; mounted+=("$root/dev"); }
bind "$rustup_home" "$root/opt/rustup" ro
bind "$repo/.git" "$root/src/terramp.git" ro
[[ -n $shared ]] && bind "$shared" "$root/home/work/shared" ro

in_root() {
    chroot "$root" /usr/bin/env -i HOME=/root TERM=xterm CARGO_HOME=/root/.cargo RUSTUP_HOME=/opt/rustup \
        PATH="/opt/rustup/toolchains/$(basename "$toolchain")/bin:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin" \
        /bin/bash -c "$1"
}
in_root 'update-ca-certificates >/dev/null 2>&1 || true'

for what in "$@"; do
    case "$what" in
        demo) command='cargo xtask demo' label=DEMO ;;
        ci) command='bash .ci/run' label=CI ;;
        *) echo "fresh_machine.sh: demo or ci, not $what" >&2; exit 2 ;;
    esac
    in_root "cd /home/work && rm -rf terramp && git clone -q /src/terramp.git terramp && cd terramp &&
        echo \"clone of \$(git log --oneline -1 | cut -c1-60)\" && start=\$(date +%s) &&
        { $command; rc=\$?; } ; echo \"$label rc=\$rc wall=\$(( \$(date +%s) - start )) s\""
done
