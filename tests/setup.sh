#!/usr/bin/env bash
# Test of the set-up: the states a newcomer's machine can be in before the README's test command, reproduced in a
# scratch RUSTUP_HOME so that the real toolchain is never touched:
#  1. the pinned toolchain without the thumbv7em-none-eabihf target (what rustup leaves when the toolchain was there
#     before rust-toolchain.toml asked for the target): the QEMU runner's preflight adds it and passes;
#  2. the same, where the runner may not install (RINGPOD_NO_INSTALL=1): it stops before building anything, with one
#     line naming the exact command;
#  3. no toolchain at all with RUSTUP_AUTO_INSTALL=0: cargo itself stops and names `rustup toolchain install`.
# Prints `N passed, N failed` and exits non-zero when a case fails.
set -uo pipefail
unset RUSTUP_TOOLCHAIN
cd "$(dirname "$0")/.."
root=$(pwd)
target=thumbv7em-none-eabihf
real_home=${RUSTUP_HOME:-$HOME/.rustup}
passed=0
failed=0
# What a program said, indented: its own `N passed, N failed` line must not count as this script's.
show() { sed 's/^/    /' <<<"$1"; }
check() { # check OK WHAT
    if [ "$1" = 0 ]; then
        echo "PASS $2"
        passed=$((passed + 1))
    else
        echo "FAIL $2"
        failed=$((failed + 1))
    fi
}

toolchain=$(rustup show active-toolchain | cut -d' ' -f1)
real_before=$(rustup target list --installed --toolchain "$toolchain" | sort)
cargo build -q --bin qemu || { echo "0 passed, 1 failed"; exit 1; }
runner=$root/target/debug/qemu

# The scratch home: the toolchain hard-linked (no copy of 1.4 GB), but the metadata rustup rewrites in place
# (lib/rustlib/components, manifests, multirust-*) copied, so that its writes never reach the real files.
scratch=$(mktemp -d "$root/target/setup-test.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
source_dir=$(readlink -f "$real_home/toolchains/$toolchain")
mkdir -p "$scratch/toolchains"
cp -a "$real_home/settings.toml" "$scratch/" 2>/dev/null || true
copy="$scratch/toolchains/$toolchain"
cp -al "$source_dir" "$copy" 2>/dev/null || { rm -rf "$copy"; cp -a "$source_dir" "$copy"; }
find "$copy/lib/rustlib" -maxdepth 1 -type f -printf '%f\n' | while read -r f; do
    cp --remove-destination "$source_dir/lib/rustlib/$f" "$copy/lib/rustlib/$f"
done

in_scratch() { RUSTUP_HOME="$scratch" RUSTUP_AUTO_INSTALL=0 "$@"; }
has_target() {
    local dir
    dir=$(in_scratch rustc --print target-libdir --target "$target" 2>/dev/null) || return 1
    compgen -G "$dir/libcore-*" >/dev/null
}
remove_target() {
    if in_scratch rustup target list --installed --toolchain "$toolchain" | grep -qx "$target"; then
        in_scratch rustup target remove --toolchain "$toolchain" "$target" >/dev/null 2>&1
    fi
    ! has_target
}

echo "== 1. the pinned toolchain without the $target target: the runner adds it"
remove_target
check $? "the scratch toolchain has no $target standard library"
out=$(in_scratch "$runner" --preflight 2>&1)
code=$?
show "$out"
check $code "the preflight passes"
grep -q "rustup target add --toolchain $toolchain $target" <<<"$out"
check $? "it said what it ran"
has_target
check $? "the $target standard library is installed afterwards"

echo "== 2. the same, where the runner may not install: one line with the command, nothing built"
remove_target
check $? "the target is removed again"
out=$(RINGPOD_NO_INSTALL=1 in_scratch "$runner" 2>&1)
code=$?
show "$out"
[ "$code" -ne 0 ]
check $? "the runner fails"
grep -qx "qemu: the $target standard library is missing: run \`rustup target add --toolchain $toolchain $target\`" <<<"$out"
check $? "it names the exact command"
! grep -q -e "Compiling" -e "PASS" -e "can't find crate" <<<"$out"
check $? "it stopped before building"
! has_target
check $? "it installed nothing"

echo "== 3. no toolchain and RUSTUP_AUTO_INSTALL=0: cargo names the command"
empty=$scratch/empty
mkdir -p "$empty/toolchains"
cp -a "$real_home/settings.toml" "$empty/" 2>/dev/null || true
out=$(RUSTUP_HOME="$empty" RUSTUP_AUTO_INSTALL=0 RUST_BACKTRACE=0 cargo --version 2>&1)
code=$?
show "$(head -3 <<<"$out")"
[ "$code" -ne 0 ] && grep -q "rustup toolchain install" <<<"$out"
check $? "cargo stops and names \`rustup toolchain install\`"

real_after=$(rustup target list --installed --toolchain "$toolchain" | sort)
[ "$real_before" = "$real_after" ]
check $? "the real toolchain's targets are unchanged"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
