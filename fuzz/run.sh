#!/usr/bin/env bash
# Runs every fuzz target (or the ones named) with cargo-fuzz on nightly, one after another.
#
#   fuzz/run.sh short [SECONDS] [TARGET...]   each target for SECONDS (default 25): CI's stage
#   fuzz/run.sh long  [RUNS]    [TARGET...]   each target for RUNS executions (default 10^7),
#                                             guarded by a time limit per target of
#                                             $GMWM_FUZZ_MAX_TIME seconds (default 3 hours)
#
# Each run starts from the committed seeds (fuzz/corpus/<target>) and writes what it finds to a
# scratch corpus outside the repository ($GMWM_FUZZ_DIR, default ${TMPDIR:-/tmp}/gmwm-fuzz),
# with its crash/timeout/OOM inputs and its log. A crash, a timeout (> 10 s), a single
# allocation beyond 512 MiB (-malloc_limit_mb: a small input must never ask for more) or a
# resident size beyond 2 GiB fails the script; the final libFuzzer figures of each target are printed as one
# line: target, executions, exec/s, cov, ft, corpus, crashes.
set -euo pipefail
cd "$(dirname "$0")"

mode=${1:-short}
shift || true
case "$mode" in
  short) limit=${1:-25}; shift || true; args=(-max_total_time="$limit") ;;
  long) limit=${1:-10000000}; shift || true; args=(-runs="$limit" -max_total_time="${GMWM_FUZZ_MAX_TIME:-10800}") ;;
  *) echo "usage: fuzz/run.sh short|long [SECONDS|RUNS] [TARGET...]" >&2; exit 2 ;;
esac
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(cargo +nightly fuzz list)
fi
scratch=${GMWM_FUZZ_DIR:-${TMPDIR:-/tmp}/gmwm-fuzz}
mkdir -p "$scratch"

# debug assertions and overflow checks on (cargo-fuzz's default), no sanitizer: the readers are
# safe Rust (files are read, none is memory-mapped), and ASan would halve the executions per second
cargo +nightly fuzz build -s none

status=0
for t in "${targets[@]}"; do
  mkdir -p "$scratch/$t/corpus" "$scratch/$t/artifacts"
  log="$scratch/$t/$mode.log"
  start=$SECONDS
  # the scratch directory outlives runs: count only what this run writes
  stamp="$scratch/$t/.started"
  touch "$stamp"
  # the seed corpus's largest input (a sqlite3 page set, a bag) sets the length bound
  max_len=$(( $(find "corpus/$t" -type f -printf '%s\n' | sort -n | tail -1) * 2 ))
  if [ "$max_len" -lt 4096 ]; then max_len=4096; fi
  if cargo +nightly fuzz run -s none "$t" "$scratch/$t/corpus" "corpus/$t" -- \
      "${args[@]}" -max_len="$max_len" -rss_limit_mb=2048 -malloc_limit_mb=512 -timeout=10 \
      -artifact_prefix="$scratch/$t/artifacts/" -print_final_stats=1 >"$log" 2>&1; then
    result=ok
  else
    result=FAILED
    status=1
  fi
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  cov=$(grep -o 'cov: [0-9]*' <<<"$last" | grep -o '[0-9]*' || true)
  ft=$(grep -o 'ft: [0-9]*' <<<"$last" | grep -o '[0-9]*' || true)
  corpus=$(grep -o 'corp: [0-9]*/[0-9]*[a-zA-Z]*' <<<"$last" | cut -d' ' -f2 || true)
  crashes=$(find "$scratch/$t/artifacts" -type f -newer "$stamp" | wc -l)
  earlier=$(find "$scratch/$t/artifacts" -type f ! -newer "$stamp" | wc -l)
  echo "$t: $result, ${execs:-?} executions, ${rate:-?} exec/s, cov ${cov:-?}, ft ${ft:-?}," \
    "corpus ${corpus:-?}, ${crashes} crash/timeout/oom inputs (${earlier} from earlier runs)," \
    "$((SECONDS - start)) s"
  if [ "$result" != ok ]; then
    tail -n 40 "$log" >&2
    echo "fuzz target $t failed: input(s) in $scratch/$t/artifacts, log $log" >&2
  fi
done
exit $status
