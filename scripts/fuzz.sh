#!/usr/bin/env bash
# Fuzzes every parser with libFuzzer (README "Fuzzing"): builds the harnesses of fuzz/ with clang
# in build-fuzz (-fsanitize=fuzzer,address,undefined) and runs each for SECONDS (default 30) over
# its committed corpus and regressions. New inputs go to build-fuzz/fuzz-corpus/NAME, findings to
# build-fuzz/fuzz-findings/NAME/ (crash-*, timeout-*, oom-*, leak-*). Exits 1 when any harness
# found something; copy the finding to fuzz/regressions/NAME/ and fix it.
#   scripts/fuzz.sh [SECONDS] [HARNESS...]     e.g. scripts/fuzz.sh 300 wire
# ISOWALL_FUZZ_SEED=N fixes libFuzzer's seed (CI does, so that a run finds something only when the
# code changed); unset, every run explores anew.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH=${1:-30}
shift || true
HARNESSES=("$@")
# hdf5 and dicom: libhdf5 1.10 (Debian 12's) reads some damaged files unsafely, and Debian's GDCM
# asserts on some structurally damaged ones. isowall reads both in a child process
# (readers/isolated_read.h), and so do these harnesses, through read_volume: a crash of the
# library is one InputError, not a finding. A finding is then anything that escapes the child:
# a crash, hang or leak of the reading process itself. Coverage guidance stops at the fork, so
# these two check the boundary on mutations of their corpus rather than explore the libraries.
[ ${#HARNESSES[@]} -gt 0 ] || HARNESSES=(nrrd store wall script wire view_protocol group_codec cell_body wall_page nifti metaimage tiff dicom hdf5 zarr)
BUILD=${ISOWALL_FUZZ_BUILD_DIR:-build-fuzz}

cmake -S . -B "$BUILD" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DISOWALL_FUZZ=ON > /dev/null
cmake --build "$BUILD" -j "$(nproc)" --target "${HARNESSES[@]/#/fuzz_}" > /dev/null

# A single allocation over -malloc_limit_mb is a finding: a parser sizes nothing from a small
# input beyond what it holds. The NRRD loader's limit is the RSS limit, since a header may rightly
# ask for a large volume; and Teem leaks a little on some failed loads (an airArray of its
# plain-text reader), which is Teem's, so leaks are not findings there.
harness_flags() {
    case "$1" in
        nrrd) echo "-malloc_limit_mb=2048 -detect_leaks=0" ;;
        # Readers of other formats: a header may rightly ask for a large volume, as NRRD's.
        nifti | dicom | tiff | zarr) echo "-malloc_limit_mb=2048" ;;
        # libhdf5 leaks a little on some failed opens (its own metadata cache), as Teem does.
        hdf5) echo "-malloc_limit_mb=2048 -detect_leaks=0" ;;
        *) echo "-malloc_limit_mb=64" ;;
    esac
}
asan_options() {
    case "$1" in
        nrrd | hdf5) echo "detect_leaks=0" ;;
        *) echo "detect_leaks=1" ;;
    esac
}

failed=()
for h in "${HARNESSES[@]}"; do
    work="$BUILD/fuzz-corpus/$h"
    findings="$BUILD/fuzz-findings/$h"
    mkdir -p "$work" "$findings"
    seeds=(fuzz/corpus/"$h")
    [ -d fuzz/regressions/"$h" ] && seeds+=(fuzz/regressions/"$h")
    dict=()
    [ -f fuzz/"$h".dict ] && dict=(-dict=fuzz/"$h".dict)
    echo "fuzz: $h for ${SECONDS_EACH}s"
    if ! ASAN_OPTIONS="$(asan_options "$h")" \
        UBSAN_OPTIONS=print_stacktrace=1 "$BUILD/fuzz/fuzz_$h" "$work" "${seeds[@]}" \
        -max_total_time="$SECONDS_EACH" -timeout=5 -rss_limit_mb=2048 -seed="${ISOWALL_FUZZ_SEED:-0}" \
        $(harness_flags "$h") "${dict[@]}" \
        -artifact_prefix="$findings/" -print_final_stats=1 > "$findings/log.txt" 2>&1; then
        failed+=("$h")
        tail -n 40 "$findings/log.txt"
    fi
    grep -E "stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb" \
        "$findings/log.txt" | sed "s/^/fuzz: $h: /" || true
    echo "fuzz: $h: corpus $(find "$work" -type f | wc -l) inputs"
done
if [ ${#failed[@]} -gt 0 ]; then
    echo "fuzz: findings in ${failed[*]}: see $BUILD/fuzz-findings/" >&2
    exit 1
fi
echo "fuzz: ${HARNESSES[*]}: no findings in ${SECONDS_EACH}s each"
