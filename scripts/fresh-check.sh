#!/usr/bin/env bash
# Fresh-machine check: the README's commands as a newcomer meets them. A clean Debian bookworm
# root (debootstrap, minbase) with only make, g++, cmake, git and ca-certificates gets a fresh
# clone of the commit under test, then runs `make deps`, `make build`, `make test` and `make run`
# in it, each phase timed and logged on its own. Anything the project needs beyond that base must
# come from scripts/install-deps.sh, or a phase fails here.
#
# Usage: scripts/fresh-check.sh [CHECKOUT] [LOGDIR]        (as root; CI runs it from .ci/run)
#   CHECKOUT  git checkout whose HEAD is tested (default: the repository this script lives in);
#             committed work only, uncommitted changes are not part of the clone
#   LOGDIR    one log per phase (default: ${TMPDIR:-/tmp}/sf-fresh-logs)
# Environment:
#   SF_FRESH_CACHE     base root tarball (default /var/cache/shadowfilter/fresh-bookworm.tgz)
#   SF_FRESH_ROOT      work root, unpacked afresh every run (default ${TMPDIR:-/tmp}/sf-fresh-root);
#                      removed after a pass, kept (unmounted) after a failure for inspection
#   SF_FRESH_SKIP_RUN  1: skip `make run`
#   SF_FRESH_BENCH_SMOKE  1: after the README's commands, `make bench-smoke` in the same tree (its
#                      deps-bench installs the benchmarks' packages only then, so they cannot hide
#                      a dependency that make test lacks); CI runs it here to build once, not twice
#   SF_FRESH_POCL_CACHE  DIR: after a pass, the root's PoCL kernel cache (/root/.cache/pocl) is
#                      moved to DIR, replacing it, for a later run of the same kernels on this
#                      machine (CI's make sanitize: PoCL compiles each kernel once, not twice)
#   CI                 passed into the root when set (the Makefile's WERROR: -Werror, as in CI)
set -uo pipefail   # no -e: every step's status is checked by hand so that it can be reported

script_dir=$(cd "$(dirname "$0")" && pwd)
proj=$(cd "${1:-$script_dir/..}" && pwd) || { echo "fresh-check: FAILED: no checkout ${1:-}"; exit 2; }
logs=${2:-${TMPDIR:-/tmp}/sf-fresh-logs}
cache=${SF_FRESH_CACHE:-/var/cache/shadowfilter/fresh-bookworm.tgz}
root=$(realpath -m "${SF_FRESH_ROOT:-${TMPDIR:-/tmp}/sf-fresh-root}")
base_pkgs=(make g++ cmake git ca-certificates)
max_age_days=30
jobs=2
t_start=$(date +%s)

fail() { echo "fresh-check: FAILED: $* after $(( $(date +%s) - t_start )) s"; exit 1; }

[ "$(id -u)" = 0 ] || fail "needs root (debootstrap, chroot, mount)"
# The root is deleted and recreated: refuse paths where a mistake would cost the host.
case "$root" in /|/tmp|/var|/var/tmp|/work|/root|/home|"") fail "SF_FRESH_ROOT=$root is not a private directory";; esac
commit=$(git -C "$proj" rev-parse --verify HEAD 2>/dev/null) || fail "$proj is not a git checkout with a commit"
mkdir -p "$logs" "$(dirname "$cache")" "$(dirname "$root")" || fail "cannot create $logs or $(dirname "$cache")"
logs=$(cd "$logs" && pwd)

# One run per work root at a time: two runs sharing it would unpack over each other's mounts.
exec 9>"$root.lock"
flock -n 9 || fail "another fresh-check holds $root.lock"

# --- mounts -------------------------------------------------------------------------------------
# The root borrows the host's /proc, /sys and /dev (PoCL reads the CPU topology from /sys). Rule:
# nothing is ever deleted under the root while one of them is mounted there, since
# `rm -rf` through the /dev or /sys bind would delete the host's.
mounts_under_root() { findmnt -rn -o TARGET | awk -v r="$root/" 'index($0, r) == 1 { print; n++ } END { exit !n }'; }
unmount_all() {
  local m
  for m in dev sys proc; do
    mountpoint -q "$root/$m" 2>/dev/null || continue
    # Recursive, then lazy if a process still holds it: a lazily detached mount leaves the tree
    # at once, so nothing below can reach the host's files any more.
    umount -R "$root/$m" 2>/dev/null || umount -R -l "$root/$m" 2>/dev/null
  done
  ! mounts_under_root >/dev/null
}
remove_root() {
  unmount_all || fail "still mounted under $root: $(mounts_under_root | tr '\n' ' '); not removing it"
  rm -rf --one-file-system "$root"
}
mount_all() {
  mount -t proc proc "$root/proc" &&
    mount --rbind /sys "$root/sys" && mount --make-rslave "$root/sys" &&
    mount --rbind /dev "$root/dev" && mount --make-rslave "$root/dev"
}
finish() {
  local rc=$?
  unmount_all || echo "fresh-check: warning: still mounted under $root: $(mounts_under_root | tr '\n' ' ')"
  exit $rc
}
trap finish EXIT
# Signals end the script through exit, so that the EXIT trap (unmounting) runs then too.
trap 'echo "fresh-check: FAILED: interrupted after $(( $(date +%s) - t_start )) s"; exit 130' INT
trap 'echo "fresh-check: FAILED: terminated after $(( $(date +%s) - t_start )) s"; exit 143' TERM

# Commands inside the root get a clean environment: a new machine has none of the host's
# variables (a host TMPDIR, for one, does not exist in the root).
in_root() {
  chroot "$root" /usr/bin/env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    HOME=/root LANG=C.UTF-8 DEBIAN_FRONTEND=noninteractive JOBS=$jobs ${CI:+CI=$CI} /bin/bash -c "$1"
}
# The host's resolver, apt sources (same mirror and suites, security updates included) and trust
# store, so the root differs from the host only in what is installed. The trust store: where the
# network passes a proxy with its own certificate authority (as on CI's machines), HTTPS from the
# root (pip filling make test's venv) needs that authority as the host does; the local
# certificates come along so that installing ca-certificates in the root keeps them.
copy_host_config() {
  cp /etc/resolv.conf "$root/etc/resolv.conf" || return 1
  if [ -d /usr/local/share/ca-certificates ]; then
    mkdir -p "$root/usr/local/share/ca-certificates" &&
      cp -a /usr/local/share/ca-certificates/. "$root/usr/local/share/ca-certificates/" || return 1
  fi
  if [ -f /etc/ssl/certs/ca-certificates.crt ]; then
    mkdir -p "$root/etc/ssl/certs" && cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/" || return 1
  fi
  if [ -f /etc/pip.conf ]; then cp /etc/pip.conf "$root/etc/pip.conf" || return 1; fi
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    cp /etc/apt/sources.list.d/debian.sources "$root/etc/apt/sources.list.d/" && rm -f "$root/etc/apt/sources.list"
  fi
}

# --- base root ----------------------------------------------------------------------------------
# The cached base holds only debootstrap's minbase and the base toolchain, never the project's
# dependencies: a warm cache must not hide a package missing from install-deps.sh. It is rebuilt
# when older than $max_age_days days or unreadable, so it follows the archive's updates.
cache_usable() {
  [ -r "$cache" ] && [ -n "$(find "$cache" -mtime -"$max_age_days" 2>/dev/null)" ] &&
    tar -tzf "$cache" ./usr/bin/g++ ./usr/bin/cmake ./usr/bin/git ./usr/bin/make >/dev/null 2>&1
}
build_base() {
  local t0 rc mirror
  t0=$(date +%s)
  rm -f "$logs/debootstrap.log" "$logs/base.log"
  command -v debootstrap >/dev/null ||
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap; } >"$logs/debootstrap.log" 2>&1 ||
    fail "cannot install debootstrap (log: $logs/debootstrap.log)"
  mirror=$(sed -n 's/^URIs: //p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -1)
  remove_root
  {
    debootstrap --variant=minbase bookworm "$root" ${mirror:+"$mirror"} >"$logs/debootstrap.log" 2>&1 ||
      { echo "debootstrap failed (log: $logs/debootstrap.log)"; false; }
  } && copy_host_config && mount_all && {
    in_root "apt-get update -qq && apt-get install -y -qq ${base_pkgs[*]} && apt-get clean" >"$logs/base.log" 2>&1 ||
      { echo "base toolchain install failed (log: $logs/base.log)"; false; }
  } && unmount_all &&
    tar -czf "$cache.part" -C "$root" . && mv "$cache.part" "$cache"
  rc=$?
  echo "fresh-check: base exit $rc in $(( $(date +%s) - t0 )) s (debootstrap --variant=minbase bookworm ${mirror:-default mirror} + ${base_pkgs[*]}; log: $logs/base.log)"
  if [ $rc != 0 ]; then
    rm -f "$cache.part"
    tail -n 20 "$logs/base.log" 2>/dev/null || tail -n 20 "$logs/debootstrap.log"
    fail "base root"
  fi
}
# A base that already has the project's key dependencies was not made by build_base.
base_is_clean() {
  ! in_root "dpkg-query -W -f='\${Status}\n' pocl-opencl-icd ocl-icd-opencl-dev libopenimageio-dev libgtest-dev 2>/dev/null | grep -q 'install ok installed'"
}
unpack_base() {
  remove_root && mkdir -p "$root" && tar -xzf "$cache" -C "$root" && copy_host_config && mount_all ||
    fail "cannot unpack $cache into $root"
}

if cache_usable; then
  echo "fresh-check: base root from $cache ($(( ($(date +%s) - $(stat -c %Y "$cache")) / 86400 )) days old)"
else
  echo "fresh-check: no usable base root at $cache (missing, unreadable or over $max_age_days days old): building it"
  build_base
fi
unpack_base
if ! base_is_clean; then
  echo "fresh-check: $cache already holds project dependencies: rebuilding it"
  build_base
  unpack_base
  base_is_clean || fail "base root holds project dependencies"
fi

# --- the commit under test ----------------------------------------------------------------------
# A real clone (not a copy of the work tree), detached at the commit read above, so that what runs
# is exactly what is committed.
[ -z "$(git -C "$proj" status --porcelain --untracked-files=no 2>/dev/null)" ] ||
  echo "fresh-check: note: $proj has uncommitted changes; they are not part of this check"
mkdir -p "$root/work"
git clone -q --no-local "$proj" "$root/work/project" >"$logs/clone.log" 2>&1 &&
  git -C "$root/work/project" checkout -q --detach "$commit" >>"$logs/clone.log" 2>&1 ||
  { cat "$logs/clone.log"; fail "git clone of $proj"; }
echo "fresh-check: testing $commit ($(git -C "$proj" log -1 --format=%s "$commit" | cut -c1-70))"

# --- phases -------------------------------------------------------------------------------------
# In order, each one timed and logged on its own; the first failure ends the check, since every
# later phase needs the earlier ones.
run_phase() {  # NAME COMMAND
  local name=$1 log="$logs/make-$1.log" t0 rc
  t0=$(date +%s)
  in_root "cd /work/project && $2" >"$log" 2>&1
  rc=$?
  echo "fresh-check: $name exit $rc in $(( $(date +%s) - t0 )) s (log: $log)"
  if [ $rc != 0 ]; then
    echo "--- last 20 lines of $log:"
    tail -n 20 "$log"
    fail "$name exit $rc"
  fi
}
rm -f "$logs"/make-*.log
run_phase deps "make deps"    # set-up: scripts/install-deps.sh installs the Debian packages
run_phase build "make build"
run_phase test "make test"
if [ "${SF_FRESH_SKIP_RUN:-0}" = 1 ]; then
  echo "fresh-check: run skipped (SF_FRESH_SKIP_RUN=1)"
else
  run_phase run "make run"
  [ -s "$root/work/project/out/spheres_esm.exr" ] || fail "make run left no out/spheres_esm.exr"
fi
if [ "${SF_FRESH_BENCH_SMOKE:-0}" = 1 ]; then
  run_phase bench-smoke "make bench-smoke"
  grep '^bench-smoke:' "$logs/make-bench-smoke.log"
fi
if [ -n "${SF_FRESH_POCL_CACHE:-}" ]; then
  rm -rf "$SF_FRESH_POCL_CACHE" && mkdir -p "$(dirname "$SF_FRESH_POCL_CACHE")" &&
    mv "$root/root/.cache/pocl" "$SF_FRESH_POCL_CACHE" ||
    fail "cannot move the root's PoCL kernel cache to $SF_FRESH_POCL_CACHE"
  echo "fresh-check: PoCL kernel cache ($(du -sh "$SF_FRESH_POCL_CACHE" | cut -f1)) moved to $SF_FRESH_POCL_CACHE"
fi

# The root is left for inspection only when a phase failed (removed at the next run's start).
remove_root
echo "fresh-check: passed in $(( $(date +%s) - t_start )) s"
