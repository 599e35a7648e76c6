#!/usr/bin/env bash
# make test-slurm: a study on a real single-node Slurm against the same study run locally.
#
# 1. Starts Slurm on this machine (scripts/slurm/cluster.sh: installs slurm-wlm and munge if
#    missing, as root; generated slurm.conf and munge key under a temporary directory).
# 2. The incline study (pipelines/incline_study.json: 6 runs) shortened to DURATION seconds
#    of El Centro (JQ_SLURM_DURATION, default 12; the whole record is 34.2 s) is run twice:
#    locally (`study plan` + `make -j2 -f runs.mk` + `study report`) and on Slurm (`study submit
#    --slurm`, a job array and the report job after it). Every run's summary must be there,
#    with its Slurm ids, and the two report.json must hold the same numbers to the last digit
#    (scripts/slurm/compare_reports.py; provenance left out).
# 3. The cluster's result directory copied elsewhere reports the same (a laptop's copy).
# 4. One run made stale and re-submitted is killed while it runs (scancel of its array
#    task): the report names it as failed with its log; a re-submit runs only that run, and
#    the report equals the local one again.
# 5. The daemons started are stopped on exit (trap).
#
# Exit status 0: passed; 1: failed; 3: Slurm cannot be started here (the reason is printed).
# With SLURM_CANNOT_START_OK=1 (.ci/run) "cannot start" prints SKIPPED with the reason and exits 0.
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
BIN=$ROOT/target/release/jointquake
DURATION=${JQ_SLURM_DURATION:-12}
source scripts/slurm/cluster.sh

cannot() {
    echo "make test-slurm: cannot start Slurm here: $*" >&2
    if [ "${SLURM_CANNOT_START_OK:-}" = 1 ]; then
        echo "make test-slurm: SKIPPED: cannot start Slurm here ($*)"
        exit 0
    fi
    exit 3
}
fail() {
    echo "make test-slurm: FAILED: $*" >&2
    exit 1
}

[ -x "$BIN" ] || fail "$BIN is not built (cargo build --release)"
T=$(mktemp -d /tmp/jq-slurm.XXXXXX)
on_exit() {
    local st=$?
    cluster_stop "$T/cluster"
    if [ $st = 0 ]; then rm -rf "$T"; else echo "make test-slurm: files kept in $T (cluster logs in $T/cluster)" >&2; fi
}
trap on_exit EXIT

reason=$(cluster_install 2>&1 >/dev/null) || cannot "$reason"
mkdir -p "$T/cluster"
echo "== starting slurmctld and slurmd on $(hostname -s) ($(nproc) CPUs) under $T/cluster"
reason=$(cluster_start "$T/cluster" 2>&1 >/dev/null) || cannot "$reason"
export SLURM_CONF=$T/cluster/slurm.conf
sinfo

# the two study files: the incline study, shortened, with its output under $T
for w in local slurm; do
    python3 - "$ROOT" "$T" "$w" "$DURATION" <<'PY'
import json, sys
root, t, w, duration = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
s = json.load(open(f"{root}/pipelines/incline_study.json"))
s["name"] = "incline_slurmtest"
s["scene"] = f"{root}/pipelines/incline.json"
s["out"] = f"{t}/{w}"
s["all"] = {"scene": {"/time/duration": duration}}
json.dump(s, open(f"{t}/{w}_study.json", "w"), indent=1)
PY
done

# wait until no job of the test cluster is queued or running (at most $1 s)
wait_jobs() {
    local i
    for i in $(seq "$1"); do
        [ -z "$(squeue -h -o %i)" ] && return 0
        sleep 1
    done
    squeue
    fail "jobs still queued or running after $1 s"
}

# the summaries' mtimes, one line per run
mtimes() { for f in "$T"/slurm/runs/*/summary.json; do echo "$f $(stat -c %Y.%y "$f")"; done; }

echo "== the study locally: plan, make -j2, report (${DURATION} s of El Centro per run)"
"$BIN" study plan "$T/local_study.json" --bin "$BIN" --cache "$T/mesh" >/dev/null
make -s -j2 -f "$T/local/runs.mk" all
"$BIN" study report "$T/local_study.json"

echo "== the study on Slurm: study submit --slurm"
"$BIN" study submit "$T/slurm_study.json" --slurm --dry-run --cache "$T/mesh" --time 00:20:00 --max-parallel 2 | tee "$T/dry.txt"
grep -q "^  JOB=\$(sbatch --parsable .*/runs.sbatch" "$T/dry.txt" || fail "the dry run prints no sbatch command"
[ -z "$(squeue -h -o %i)" ] || fail "the dry run submitted a job"
"$BIN" study submit "$T/slurm_study.json" --slurm --cache "$T/mesh" --time 00:20:00 --max-parallel 2 | tee "$T/submit1.txt"
grep -q "6 of 6 runs to do (array 0-5%2)" "$T/submit1.txt" || fail "the first submit does not run the 6 runs"
wait_jobs 1200
ls "$T"/slurm/slurm/
python3 - "$T/slurm" <<'PY' || fail "summaries"
import json, sys, os
out = sys.argv[1]
plan = json.load(open(f"{out}/plan.json"))
assert len(plan["runs"]) == 6, len(plan["runs"])
for k, r in enumerate(plan["runs"]):
    s = json.load(open(os.path.join(r["dir"], "summary.json")))
    p = s["provenance"]
    assert p["slurm"]["array_task_id"] == str(k), (r["id"], p)
    print(f"  {r['id']:18} task {p['slurm']['array_job_id']}_{p['slurm']['array_task_id']} on {p['host']}, {s['threads']} thread, {s['wall_time']:.1f} s, jointquake {p['version']} {p['commit'][:12]}")
PY
grep -q "^## Cost" "$T/slurm/report.md" || fail "the report has no cost section"
python3 scripts/slurm/compare_reports.py "$T/local/report.json" "$T/slurm/report.json" || fail "the Slurm report differs from the local one"
echo "  cost, local: $(sed -n '/^## Cost/{n;n;p}' "$T/local/report.md")"
echo "  cost, Slurm: $(sed -n '/^## Cost/{n;n;p}' "$T/slurm/report.md")"

echo "== the cluster's results copied elsewhere report the same"
cp -a "$T/slurm" "$T/copy"
sed "s#\"$T/slurm\"#\"$T/copy\"#" "$T/slurm_study.json" > "$T/copy_study.json"
"$BIN" study report "$T/copy_study.json" >/dev/null
python3 scripts/slurm/compare_reports.py "$T/local/report.json" "$T/copy/report.json" || fail "the copied directory reports differently"

echo "== one run killed on purpose (scancel of its array task) is named as failed; a re-submit redoes only it"
victim=$(python3 -c "import json; print(json.load(open('$T/slurm/plan.json'))['runs'][2]['id'])")
touch "$T/slurm/scenes/$victim.json"   # stale: its scene is newer than its result
mtimes | grep -v "/$victim/" > "$T/mtimes_before.txt"
"$BIN" study submit "$T/slurm_study.json" --slurm --cache "$T/mesh" --time 00:20:00 | tee "$T/submit2.txt"
grep -q "1 of 6 runs to do (array 2)" "$T/submit2.txt" || fail "the stale run is not the only one submitted"
job=$(sed -n 's/^submitted: array job \([0-9]*\).*/\1/p' "$T/submit2.txt")
# kill it while jointquake runs: its task is running and its old summary is removed
for i in $(seq 600); do
    [ "$(squeue -h -j "${job}_2" -o %t 2>/dev/null)" = R ] && [ ! -e "$T/slurm/runs/$victim/summary.json" ] && break
    sleep 0.2
done
sleep 1
scancel "${job}_2"
echo "scancel ${job}_2 ($victim)"
wait_jobs 300
# scancel sends SIGTERM: the run finishes its current output and writes summary.json marked
# `interrupted` (docs/cli.md), so a killed run has either no summary or an interrupted one
python3 -c "import json,sys; s=json.load(open(sys.argv[1])); sys.exit(0 if s.get('interrupted') is not None else 1)" "$T/slurm/runs/$victim/summary.json" 2>/dev/null \
    || [ ! -e "$T/slurm/runs/$victim/summary.json" ] \
    || fail "the killed run finished before scancel (make JQ_SLURM_DURATION longer)"
python3 - "$T/slurm/report.json" "$victim" "$T/slurm/runs/$victim.log" <<'PY' || fail "the killed run is not named as failed with its log"
import json, sys
rep, victim, log = json.load(open(sys.argv[1])), sys.argv[2], sys.argv[3]
st = {r["id"]: r for r in rep["runs"]}
v = st[victim]
assert v["status"] == "failed" and "killed by Slurm" in v["message"] and log in v["message"], v
others = [r for r in rep["runs"] if r["id"] != victim]
assert all(r["status"] == "finished" for r in others), others
print(f"  report: {victim}: failed: {v['message']}")
PY
grep -q "$victim" "$T/slurm/report.md" || fail "report.md does not name $victim"

"$BIN" study submit "$T/slurm_study.json" --slurm --cache "$T/mesh" --time 00:20:00 | tee "$T/submit3.txt"
grep -q "1 of 6 runs to do (array 2)" "$T/submit3.txt" || fail "the re-submit does not run only the killed run"
grep -q "$victim (not finished)" "$T/submit3.txt" || fail "the re-submit does not say the killed run did not finish"
wait_jobs 600
[ -e "$T/slurm/runs/$victim/summary.json" ] || fail "the re-submitted run has no summary"
mtimes | grep -v "/$victim/" | diff "$T/mtimes_before.txt" - || fail "runs other than $victim were redone"
python3 scripts/slurm/compare_reports.py "$T/local/report.json" "$T/slurm/report.json" || fail "after the re-submit the report differs from the local one"
echo "make test-slurm: all checks passed"
