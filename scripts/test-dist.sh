#!/usr/bin/env bash
# The master on every platform (a stage of the test command): builds the release archives
# (scripts/dist.sh: nothing recompiles when the main command built them in the same target
# folder), checks them against SHA256SUMS, unpacks them, and runs the 30 s closed loop
# (target/ssp/nigel_closed_loop.ssp, whose FMUs carry every platform's libraries) with each
# executable build: x86-64 Linux natively (in process, --isolate, --isolate=run: the
# reference, each byte for byte equal), x86-64 Windows under wine (its FMUs' win64 libraries,
# whose C library rounds sin, cos, atan2, hypot otherwise in the last bit:
# scripts/compare-platform-csv.py says how many values differ and holds each within 1e-12 of
# its column's largest magnitude; and equal bit for bit to the plain C importer on the same
# DLLs), aarch64 Linux under qemu-user (in process and --isolate, compared as Windows). The
# macOS builds are checked as built (Mach-O headers: no Mac here).
# NIGEL_DIST_PLATFORMS (build-dist's list: linux64,win64,aarch64-linux,darwin64; default all)
# limits it to those platforms' archives (linux64, the reference, always).
set -euo pipefail
. "$(dirname "$0")/target-dir.sh"
version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$repo/Cargo.toml" | head -1)"
ssp="$target/ssp/nigel_closed_loop.ssp"
[ -f "$ssp" ] || { echo "test-dist: no $ssp (build-fmu writes it)" >&2; exit 1; }
platforms="${NIGEL_DIST_PLATFORMS:-linux64,win64,aarch64-linux,darwin64}"
case ",$platforms," in *,linux64,*) ;; *) platforms="linux64,$platforms" ;; esac
wanted() { case ",$platforms," in *,"$1",*) return 0 ;; *) return 1 ;; esac; }
rm -f "$target"/dist/cosim-*.tar.gz "$target"/dist/cosim-*.zip
bash "$repo/scripts/dist.sh" --platforms "$platforms" >/dev/null
work="$target/dist-test"
rm -rf "$work" && mkdir -p "$work"
(cd "$target/dist" && sha256sum -c --quiet SHA256SUMS)
linux_x86="x86_64-unknown-linux-gnu" windows="x86_64-pc-windows-gnu" linux_arm="aarch64-unknown-linux-gnu"
for archive in "$target"/dist/cosim-*.tar.gz; do tar -C "$work" -xzf "$archive"; done
if wanted win64; then (cd "$work" && unzip -q "$target/dist/cosim-$version-$windows.zip"); fi
dir() { echo "$work/cosim-$version-$1"; }
run_args=(run "$ssp" --stop-time 30 --step 1e-3 --algorithm ordered --output-interval 0.01)
same() { # same NAME CSV: byte for byte equal to the reference
    if cmp -s "$work/reference.csv" "$2"; then
        echo "identical to x86-64 Linux: $1"
    else
        echo "test-dist: $1 differs from the x86-64 Linux run:" >&2
        cmp "$work/reference.csv" "$2" >&2 || true
        diff <(head -c 2000 "$work/reference.csv") <(head -c 2000 "$2") | head -5 >&2 || true
        exit 1
    fi
}

# compared REFERENCE OTHER NAME: compare-platform-csv.py's line, and docs/platforms.md must
# print its count of differing values ("N of the M values")
compared() {
    local line counts
    line=$(python3 "$repo/scripts/compare-platform-csv.py" "$@")
    echo "$line"
    counts=$(echo "$line" | python3 -c 'import re,sys; m=re.search(r"(\d+) of (\d+) values", sys.stdin.read()); print(f"{int(m[1]):,} of the {int(m[2]):,}" if m else "byte-equal")')
    tr '\n' ' ' <"$repo/docs/platforms.md" | sed 's/  */ /g' | grep -qF "$counts" \
        || { echo "test-dist: docs/platforms.md does not print this run's count for $3 ($counts)" >&2; exit 1; }
}

# x86-64 Linux, the release build (glibc 2.17): the reference, and its isolated runs
"$(dir $linux_x86)/cosim" "${run_args[@]}" --output "$work/reference.csv"
"$(dir $linux_x86)/cosim" "${run_args[@]}" --isolate --output "$work/linux-isolate.csv"
same "x86-64 Linux --isolate" "$work/linux-isolate.csv"
"$(dir $linux_x86)/cosim" "${run_args[@]}" --isolate=run --output "$work/linux-isolate-run.csv"
same "x86-64 Linux --isolate=run" "$work/linux-isolate-run.csv"

if wanted win64; then
    # x86-64 Windows under wine (the ProcessPrng shim next to the program: wine 8 lacks it)
    x86_64-w64-mingw32-gcc -shared -O2 -o "$(dir $windows)/bcryptprimitives.dll" \
        "$repo/build-fmu/tests/c/process_prng_shim.c" -lbcrypt
    wine_path() { echo "Z:${1//\//\\}"; }
    wine_cosim() {
        env -u DISPLAY -u WAYLAND_DISPLAY WINEPREFIX="$target/wine-prefix" WINEDEBUG=-all \
            WINEDLLOVERRIDES="mscoree,mshtml=;bcryptprimitives=n" wine "$(dir $windows)/cosim.exe" "$@"
    }
    wine_cosim run "$(wine_path "$ssp")" "${run_args[@]:2}" --output "$(wine_path "$work/windows.csv")"
    compared "$work/reference.csv" "$work/windows.csv" "x86-64 Windows (wine)"
    # --isolate is refused on Windows, naming the platform, before anything loads
    if wine_cosim run "$(wine_path "$ssp")" --stop-time 1 --isolate 2>"$work/windows-isolate.err"; then
        echo "test-dist: cosim.exe --isolate exited 0" >&2
        exit 1
    fi
    grep -q "available on Linux only, not on Windows" "$work/windows-isolate.err" \
        || { cat "$work/windows-isolate.err" >&2; echo "test-dist: cosim.exe --isolate: not the refusal" >&2; exit 1; }
    echo "refused on Windows: --isolate ($(tr -d '\r' <"$work/windows-isolate.err" | head -1))"
fi

if wanted aarch64-linux; then
    # aarch64 Linux: the programs are aarch64 ELF executables needing no glibc symbol version
    # above 2.17, and run under qemu-user with one build of arm64 glibc (Debian's cross package:
    # loader and libraries; see QEMU_ENV in build-fmu/tests/platforms.rs for why a mix of builds
    # hangs the first thread's start): in process and --isolate (each FMU's cosim-host under
    # qemu too, through a wrapper named by NIGEL_COSIM_HOST: qemu-user cannot exec a foreign
    # program without binfmt_misc; --isolate=run re-executes cosim itself, which therefore is not
    # run here), compared with x86-64 Linux as the Windows run is, --isolate byte for byte equal
    # to the in-process run
    for p in cosim cosim-host campaign; do
        exe="$(dir $linux_arm)/$p"
        aarch64-linux-gnu-readelf -h "$exe" | grep -Eq "Class: +ELF64" && aarch64-linux-gnu-readelf -h "$exe" | grep -Eq "Machine: +AArch64" \
            || { echo "test-dist: $exe: not a 64-bit AArch64 ELF file" >&2; exit 1; }
        highest=$(aarch64-linux-gnu-objdump -T "$exe" | grep -o 'GLIBC_2\.[0-9]*' | sort -t. -k2 -n | tail -1)
        [ "${highest#GLIBC_2.}" -le 17 ] || { echo "test-dist: $exe needs $highest" >&2; exit 1; }
        echo "aarch64 ELF executable, glibc symbols up to $highest: $exe"
    done
    export QEMU_LD_PREFIX=/usr/aarch64-linux-gnu QEMU_SET_ENV=LD_LIBRARY_PATH=/usr/aarch64-linux-gnu/lib
    printf '#!/bin/sh\nexec qemu-aarch64 "%s" "$@"\n' "$(dir $linux_arm)/cosim-host" >"$work/cosim-host-under-qemu"
    chmod +x "$work/cosim-host-under-qemu"
    qemu-aarch64 "$(dir $linux_arm)/cosim" "${run_args[@]}" --output "$work/aarch64.csv"
    compared "$work/reference.csv" "$work/aarch64.csv" "aarch64 Linux (qemu)"
    NIGEL_COSIM_HOST="$work/cosim-host-under-qemu" qemu-aarch64 "$(dir $linux_arm)/cosim" "${run_args[@]}" --isolate \
        --output "$work/aarch64-isolate.csv"
    cmp "$work/aarch64.csv" "$work/aarch64-isolate.csv" || { echo "test-dist: aarch64 --isolate differs from in process" >&2; exit 1; }
    echo "identical to aarch64 in process: aarch64 Linux --isolate (qemu)"
    unset QEMU_LD_PREFIX QEMU_SET_ENV
fi

# each non-x86-64 master equals, bit for bit, the plain C importer
# (build-fmu/tests/c/fmi2_closed_loop.c) on the same libraries (Jacobi, every output at every
# step): Windows (mingw-w64, under wine, the same DLLs), aarch64 (aarch64-linux-gnu-gcc,
# under qemu, in process and --isolate): the differences from x86-64 Linux above are the
# FMUs' C library's, not the master's (the test executable of the test command's build when
# it names one, else built here)
if [ -n "${NIGEL_TEST_EXECUTABLES:-}" ]; then
    platforms_test="$(python3 "$repo/scripts/test-executables.py" "$NIGEL_TEST_EXECUTABLES" build-fmu platforms)"
else
    platforms_test="$(cd "$repo" && cargo test --release -p build-fmu --test platforms --no-run --message-format=json \
        | python3 scripts/test-executables.py - build-fmu platforms)"
fi
master_tests=()
wanted win64 && master_tests+=(windows_master_under_wine_equals_the_c_importer_on_the_same_dlls_bit_for_bit)
wanted aarch64-linux && master_tests+=(aarch64_master_under_qemu_equals_the_c_importer_on_the_same_libraries_bit_for_bit)
if [ ${#master_tests[@]} -gt 0 ]; then
    (cd "$repo/build-fmu" && NIGEL_DIST_DIR="$work" "$platforms_test" --quiet --ignored --exact "${master_tests[@]}")
fi

if wanted darwin64; then
    # macOS: the Mach-O header of each program (64-bit magic, CPU type), its minimum macOS,
    # its libraries (docs/platforms.md must name them as macho-check.py prints them) and, on
    # arm64, its signature
    for arch in x86_64 aarch64; do
        for p in cosim cosim-host campaign; do
            line=$(python3 "$repo/scripts/macho-check.py" "$(dir "$arch-apple-darwin")/$p" "$arch")
            echo "$line"
            libs=$(echo "$line" | sed -n 's/.*system libraries only (\(.*\)): .*/\1/p')
            tr '\n' ' ' <"$repo/docs/platforms.md" | sed 's/  */ /g' | grep -qF "system libraries only: $libs" \
                || { echo "test-dist: docs/platforms.md does not print the libraries of $arch $p ($libs)" >&2; exit 1; }
        done
    done
fi
