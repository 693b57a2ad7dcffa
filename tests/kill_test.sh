#!/bin/bash
# The kill test (issue 20): `kartograf map SEQ --out O --force` is interrupted by SIGINT, SIGTERM
# and SIGHUP at MOMENTS moments each, spread over the computing and the writing, and O must then
# hold exactly the previous set or exactly the new one, with no staging folder or temporary file
# beside or inside it.
#   usage: kill_test.sh KARTOGRAF WORKDIR [MOMENTS]
# The previous set is made with other options than the new one (--resolution 0.1), so that a mix
# of the two would show in the checksums. The new set is a reference run's: map is deterministic
# but for the timings in report.json, report.html and rooms.json, which must differ from the
# previous set's (and report.json parse).
set -u
kartograf=$1
work=$2
moments=${3:-20}
rm -rf "$work" && mkdir -p "$work" || exit 1
cd "$work" || exit 1

"$kartograf" synth --out seq --frames 20 --width 320 --height 240 > /dev/null 2>&1 || {
  echo "FAIL: synth"; exit 1; }
map() { "$kartograf" map seq --backend cpu --no-progress "$@"; }
checksums() { (cd "$1" && find . -type f | LC_ALL=C sort | xargs md5sum); }
timed='\./\(report\.json\|report\.html\|rooms\.json\)$'
untimed() { grep -v "$timed" "$1"; }
# Whether the folder $1 (its checksums in $1.md5) is a complete new set.
is_new_set() {
  untimed "$1.md5" | cmp -s - <(untimed new.md5) || return 1
  [ "$(grep -c "$timed" "$1.md5")" = 3 ] || return 1
  local line
  while read -r line; do grep -qxF "$line" previous.md5 && return 1; done < <(grep "$timed" "$1.md5")
  python3 -c 'import json, sys; json.load(open(sys.argv[1]))' "$1/report.json" 2> /dev/null
}
now_ms() { echo $(( $(date +%s%N) / 1000000 )); }

map --out previous --resolution 0.1 > /dev/null 2>&1 || { echo "FAIL: the previous set"; exit 1; }
start=$(now_ms)
map --out new > new.log 2>&1 || { cat new.log; echo "FAIL: the new set"; exit 1; }
duration=$(( $(now_ms) - start ))
map --out new2 > /dev/null 2>&1 || { echo "FAIL: a second new set"; exit 1; }
checksums previous > previous.md5
checksums new > new.md5
checksums new2 | untimed /dev/stdin | cmp -s - <(untimed new.md5) || { echo "FAIL: map is not deterministic"; exit 1; }
cmp -s previous.md5 new.md5 && { echo "FAIL: the two sets are the same"; exit 1; }
test -f new/.kartograf-run || { echo "FAIL: no run marker"; exit 1; }
echo "map takes ${duration} ms; $(wc -l < new.md5) files per set"

# Waits (polling) until the run's staging folder holds $1, at most 10 s.
wait_for_staged() {
  local i
  for i in $(seq 10000); do
    for f in .out.kartograf-staging-"$pid"/$1; do [ -e "$f" ] && return 0; done
    kill -0 "$pid" 2> /dev/null || return 0
    sleep 0.001
  done
}

# Moment k of $moments: the first ~60 % at fractions of the run's time, the rest once the files
# are being written (after the first, the map, the report, the marker) and just after the end.
wait_for_moment() {
  local k=$1 computing=$(( moments * 6 / 10 ))
  if [ "$k" -lt "$computing" ]; then
    sleep "$(awk -v k="$k" -v n="$computing" -v d="$duration" 'BEGIN { printf "%.3f", d * (k + 1) / (n + 1) / 1000 }')"
    return
  fi
  case $(( (k - computing) % 8 )) in
    0) wait_for_staged trajectory.txt ;;
    1) wait_for_staged trajectory.txt; sleep 0.003 ;;
    2) wait_for_staged map.ply ;;
    3) wait_for_staged planes.json ;;
    4) wait_for_staged report.json ;;
    5) wait_for_staged .kartograf-run ;;
    6) wait_for_staged report.html ;;
    7) sleep "$(awk -v d="$duration" 'BEGIN { printf "%.3f", d * 1.05 / 1000 }')" ;;
  esac
}

failures=0
for signal in INT TERM HUP; do
  number=$(kill -l "$signal")
  kept=0 replaced=0 handled=0
  for k in $(seq 0 $(( moments - 1 ))); do
    rm -rf out && cp -a previous out || exit 1
    # A script's background jobs start with SIGINT ignored; the CLI keeps ignored signals ignored.
    env --default-signal=INT,TERM,HUP "$kartograf" map seq --backend cpu --no-progress --out out \
      --force > run.log 2>&1 &
    pid=$!
    wait_for_moment "$k"
    kill -s "$signal" "$pid" 2> /dev/null
    wait "$pid"
    rc=$?
    checksums out > out.md5
    problem=""
    grep -q "kartograf: interrupted (SIG$signal)" run.log && handled=$((handled + 1))
    if cmp -s out.md5 previous.md5; then
      kept=$((kept + 1))
      # Without the message: the signal came before main() (the default action, nothing done).
      [ "$rc" = $((128 + number)) ] || problem="the previous set but exit status $rc"
    elif is_new_set out; then
      replaced=$((replaced + 1))
      [ "$rc" = 0 ] || { [ "$rc" = $((128 + number)) ] && grep -q "interrupted" run.log; } ||
        problem="the new set but exit status $rc"
    else
      problem="a mix: $(diff previous.md5 out.md5 | head -3 | tr '\n' ' ')"
    fi
    leftovers=$(find . -maxdepth 1 -name '.*kartograf-*'; find out -name '*.tmp-*' -o -name '.*kartograf-*' ! -name .kartograf-run)
    [ -z "$leftovers" ] || problem="$problem leftovers: $leftovers"
    if [ -n "$problem" ]; then
      failures=$((failures + 1))
      echo "FAIL: SIG$signal at moment $k: $problem"
      cat run.log
    fi
  done
  echo "SIG$signal: $moments moments: previous set kept $kept, new set complete $replaced," \
    "$handled handled by kartograf, failures so far $failures"
  [ "$handled" -ge $((moments / 2)) ] || { failures=$((failures + 1)); echo "FAIL: SIG$signal: handled only $handled times"; }
done
[ "$failures" = 0 ]
