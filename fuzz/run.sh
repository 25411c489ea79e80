#!/usr/bin/env bash
# Runs nacre's fuzz targets with cargo-fuzz on the stable toolchain (`-s none`: libFuzzer's
# coverage instrumentation only, no sanitizer, so no nightly `-Z` flag is needed).
#
#   fuzz/run.sh SECONDS [TARGET...]      # every target when none is named
#
# Each target runs SECONDS seconds from the committed seeds (seeds/TARGET) plus whatever a
# previous local run left in corpus/TARGET; a crash stops the run with the input saved under
# artifacts/TARGET/ and a non-zero exit status. Extra libFuzzer flags: FUZZ_FLAGS.
set -euo pipefail
cd "$(dirname "$0")"
seconds=${1:?usage: fuzz/run.sh SECONDS [TARGET...]}
shift
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(recipe material manifest flags exr ktx2 png)
fi
triple=$(rustc -vV | sed -n 's/^host: //p')
# cargo puts the binaries under CARGO_TARGET_DIR when it is set (relative to this folder).
target_dir=${CARGO_TARGET_DIR:-target}
# -a: debug assertions (integer overflow checks) in the instrumented build.
cargo fuzz build -s none -O -a
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t" "artifacts/$t"
    echo "fuzz/run.sh: $t for ${seconds} s" >&2
    # shellcheck disable=SC2086
    "$target_dir/$triple/release/$t" "corpus/$t" "seeds/$t" \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=20 \
        -artifact_prefix="artifacts/$t/" -print_final_stats=1 ${FUZZ_FLAGS:-} \
        2>"artifacts/$t/log.txt" || {
        tail -n 40 "artifacts/$t/log.txt" >&2
        echo "fuzz/run.sh: $t failed; the input is in fuzz/artifacts/$t/" >&2
        exit 1
    }
    grep -E '^(Done|stat::)' "artifacts/$t/log.txt" >&2 || true
done
