#!/usr/bin/env bash
# The master's release archives: cosim, cosim-host and campaign for x86-64 Linux (glibc 2.17),
# x86-64 Windows, aarch64 Linux (glibc 2.17), x86-64 and arm64 macOS, built with the FMUs'
# recipes (build-fmu's Platform, by `build-dist`) into target/dist/:
#   cosim-<version>-<triple>.tar.gz (.zip for Windows), each a folder of that name holding the
#   programs and the licenses, and SHA256SUMS (`sha256sum -c SHA256SUMS` checks them).
# Archives are byte-identical from the same binaries (sorted, time stamps and owners fixed).
# Usage: bash scripts/dist.sh [--platforms LIST]   (LIST as build-dist's: linux64,win64,...)
set -euo pipefail
. "$(dirname "$0")/target-dir.sh"
dist="$target/dist"
rm -rf "$dist/stage"
folders=$(cd "$repo" && cargo run --release --quiet -p build-fmu --bin build-dist -- "$@" "$dist/stage")
for folder in $folders; do
    name=$(basename "$folder")
    rm -f "$dist/$name.tar.gz" "$dist/$name.zip"
    # every file dated 2000-01-01 (zip cannot hold earlier), owners 0
    find "$folder" -exec touch -h -d 2000-01-01T00:00:00Z {} +
    case "$name" in
        *windows*) (cd "$dist/stage" && TZ=UTC zip -q -X -r "$dist/$name.zip" "$name") ;;
        *) tar -C "$dist/stage" --sort=name --owner=0 --group=0 --numeric-owner --mode=u+rwX,go+rX,go-w \
            -cf - "$name" | gzip -9 -n >"$dist/$name.tar.gz" ;;
    esac
done
(cd "$dist" && sha256sum cosim-*.tar.gz cosim-*.zip 2>/dev/null >SHA256SUMS.tmp || true; mv SHA256SUMS.tmp SHA256SUMS)
cat "$dist/SHA256SUMS"
