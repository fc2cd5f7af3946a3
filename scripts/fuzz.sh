#!/usr/bin/env bash
# Runs every libFuzzer target of fuzz/ (built by scripts/sanitize.sh into build-sanitize/) for a
# bounded time each, two at a time, starting from the seed corpora in fuzz/corpus/ and the
# dictionaries fuzz/obj.dict and fuzz/json.dict (engine, the generated-mesh target, takes none).
# New inputs are kept in build-sanitize/fuzz-corpus/<target> (so later runs continue from
# them); a crash, leak, sanitizer report or timeout leaves its input in
# build-sanitize/fuzz-findings/ and fails the script. Prints one line per target: executions,
# coverage, corpus size.
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     (default 60 s, every target)
#   LIMN_FUZZ_RUNS=10000000 scripts/fuzz.sh 0 obj_reader  (a fixed number of executions)
#   LIMN_FUZZ_MAX_LEN=4096 ...                              (smaller inputs, more executions)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift $(( $# > 0 ? 1 : 0 ))
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(obj_reader json_mesh render_request silhouette_request implicit_request config engine
  mesh_import)
for target in "${targets[@]}"; do
  [ -x "build-sanitize/bin/${target}_fuzz" ] || { scripts/sanitize.sh -N >/dev/null; break; }
done
mkdir -p build-sanitize/fuzz-findings build-sanitize/fuzz-logs
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp"

run_target() {
  local target=$1
  local corpus="build-sanitize/fuzz-corpus/$target"
  mkdir -p "$corpus"
  local limit=(-max_total_time="$seconds")
  [ -n "${LIMN_FUZZ_RUNS:-}" ] && limit=(-runs="$LIMN_FUZZ_RUNS")
  # 64 KiB inputs reach every field; 2 GiB and 10 s per input bound what one input may cost.
  local options=(-max_len="${LIMN_FUZZ_MAX_LEN:-65536}" -rss_limit_mb=2048 -timeout=10)
  case "$target" in
    obj_reader) options+=(-dict=fuzz/obj.dict) ;;
    # engine: the input is the mesh generator's choices, not text (no dictionary); 4 KiB of
    # them make meshes of up to 200 faces. Each input renders every method (Mesa's llvmpipe
    # loaded, so no leak detection: see scripts/sanitize.sh) within a 20 s deadline of its own
    # (fuzz/engine_fuzz.cpp), hence more time and memory; past 120 s a stage ignored it.
    engine) options=(-max_len="${LIMN_FUZZ_MAX_LEN:-4096}" -rss_limit_mb=4096 -timeout=120) ;;
    # mesh_import: binary and text formats alike (the first byte picks one); no dictionary.
    mesh_import) ;;
    *) options+=(-dict=fuzz/json.dict) ;;
  esac
  local asan="$ASAN_OPTIONS"
  [ "$target" = engine ] && asan="detect_leaks=0:abort_on_error=1"
  ASAN_OPTIONS="$asan" "build-sanitize/bin/${target}_fuzz" "${limit[@]}" "${options[@]}" \
    -print_final_stats=1 \
    -artifact_prefix="build-sanitize/fuzz-findings/${target}-" \
    "$corpus" "fuzz/corpus/$target" >"build-sanitize/fuzz-logs/$target.log" 2>&1
}

summary() {
  local log="build-sanitize/fuzz-logs/$1.log"
  local runs cov units
  runs=$(awk '/stat::number_of_executed_units/ {print $NF}' "$log")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | awk '{print $2}')
  units=$(find "build-sanitize/fuzz-corpus/$1" -type f | wc -l)
  printf '%-20s %12s executions  coverage %6s edges  corpus %5s inputs  %s\n' \
    "$1" "${runs:-?}" "${cov:-?}" "$units" "$2"
}

failed=0
pids=()
names=()
for target in "${targets[@]}"; do
  run_target "$target" &
  pids+=($!)
  names+=("$target")
  # Two at a time: the machine has two cores.
  if [ ${#pids[@]} -eq 2 ]; then
    for i in 0 1; do
      if wait "${pids[$i]}"; then summary "${names[$i]}" ok; else summary "${names[$i]}" FOUND; failed=1; fi
    done
    pids=()
    names=()
  fi
done
for i in "${!pids[@]}"; do
  if wait "${pids[$i]}"; then summary "${names[$i]}" ok; else summary "${names[$i]}" FOUND; failed=1; fi
done
if [ $failed -ne 0 ]; then
  echo "fuzz: findings in build-sanitize/fuzz-findings/ (logs in build-sanitize/fuzz-logs/)" >&2
  ls build-sanitize/fuzz-findings >&2
fi
exit $failed
