"""The cluster job scripts in jobs/: shellcheck-clean, and their restart/resubmit logic run
without a cluster. Fake srun/mpiexec, sbatch/qsub, squeue/scontrol/qstat executables on PATH
record what the scripts ask of the batch system; a resubmission is followed by running the
recorded submission (script, arguments, environment) as the next job of the chain. The last
tests drive the real morphogen binary through a checkpoint on SIGUSR1 and a restart, and through
a chunked sweep (sweep_array.sbatch)."""
import glob
import os
import shutil
import signal
import subprocess
import time

import pytest

SOURCE = os.path.abspath(os.environ.get("MORPHOGEN_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "../..")))
JOBS = os.path.join(SOURCE, "jobs")
EXE = os.environ.get("MORPHOGEN_EXE", os.path.join(SOURCE, "build", "morphogen"))
MPIEXEC = shutil.which(os.environ.get("MORPHOGEN_MPIEXEC", "mpiexec")) or "mpiexec"  # before the fakes go on PATH
DECK = os.path.join(SOURCE, "input", "turing_spots.yaml")
SCRIPTS = sorted(glob.glob(os.path.join(JOBS, "*.sbatch")) + glob.glob(os.path.join(JOBS, "*.pbs"))
                 + glob.glob(os.path.join(JOBS, "*.sh")))

# Fake srun / mpiexec: records its arguments (one per line) and the signals it gets; exit code of
# call n is the n-th word of FAKE_EXIT_CODES (the last one repeats). With FAKE_WAIT_SIGNAL=1 it
# waits for FAKE_SIGNALS_NEEDED (default 1) signals, SIGUSR1 or SIGTERM, first. On exit code 3 it leaves a checkpoint in -output_dir, as
# morphogen would (unless FAKE_CHECKPOINT=0). Sweeps: call n writes the finished points listed in
# the n-th ";"-separated field of FAKE_POINTS (point indices) as -output_dir/points/point_NNNNNN.json.
FAKE_LAUNCHER = r"""#!/bin/bash
state=$FAKE_STATE
n=$(( $(cat "$state/launch.count" 2>/dev/null || echo 0) + 1 ))
echo "$n" > "$state/launch.count"
printf '%s\n' "$@" > "$state/launch.args.$n"
printf '%s\n' "${HWLOC_COMPONENTS-unset}" "${OMPI_MCA_odls_base_sigkill_timeout-unset}" > "$state/launch.env.$n"
read -r -a codes <<< "${FAKE_EXIT_CODES:-0}"
code=${codes[n-1]:-${codes[-1]}}
out=""; prev=""
for a in "$@"; do [[ $prev == -output_dir ]] && out=$a; prev=$a; done
if [[ ${FAKE_WAIT_SIGNAL:-0} == 1 ]]; then
  got=0
  trap 'echo USR1 >> "$state/launch.signals"; got=$((got + 1))' USR1
  trap 'echo TERM >> "$state/launch.signals"; got=$((got + 1))' TERM
  echo $$ > "$state/launch.ready"
  while ((got < ${FAKE_SIGNALS_NEEDED:-1})); do sleep 0.02; done
fi
IFS=';' read -r -a points <<< "${FAKE_POINTS:-}"
for p in ${points[n-1]:-}; do
  mkdir -p "$out/points" && : > "$out/points/$(printf 'point_%06d.json' "$p")"
done
if [[ ($code == 3 || ${FAKE_RANKS_EXIT:-} == 3) && ${FAKE_CHECKPOINT:-1} == 1 && -n $out ]]; then
  : > "$out/$(printf 'checkpoint_%07d.vtkhdf' $((n * 100)))"
fi
# The ranks' own exit code (rank 0 writes it to MORPHOGEN_EXIT_FILE), when it is not the launcher's.
if [[ -n ${FAKE_RANKS_EXIT:-} && -n ${MORPHOGEN_EXIT_FILE:-} ]]; then echo "$FAKE_RANKS_EXIT" > "$MORPHOGEN_EXIT_FILE"; fi
exit "$code"
"""

# With FAKE_RANKS_EXIT the ranks' exit code is written to $MORPHOGEN_EXIT_FILE, as morphogen's
# rank 0 does (cli/exit_file.hpp), while the launcher exits with FAKE_EXIT_CODES.

# Fake sbatch / qsub: records arguments, environment and working directory of each submission.
FAKE_SUBMIT = r"""#!/bin/bash
state=$FAKE_STATE
n=$(( $(cat "$state/submit.count" 2>/dev/null || echo 0) + 1 ))
echo "$n" > "$state/submit.count"
printf '%s\n' "$@" > "$state/submit.args.$n"
env -0 > "$state/submit.env.$n"
pwd > "$state/submit.cwd.$n"
if [[ ${FAKE_SUBMIT_RC:-0} != 0 ]]; then echo "submission refused" >&2; exit "$FAKE_SUBMIT_RC"; fi
echo "Submitted batch job $((2000 + n))"
"""

FAKE_SQUEUE = r"""#!/bin/bash
[[ -n ${FAKE_SQUEUE:-} ]] || { echo "squeue: error: no such job" >&2; exit 1; }
echo "$FAKE_SQUEUE"
"""

FAKE_SCONTROL = r"""#!/bin/bash
[[ -n ${FAKE_SCONTROL:-} ]] || exit 1
printf 'JobId=%s JobName=morphogen\n   %s\n' "$3" "$FAKE_SCONTROL"
"""

FAKE_QSTAT = r"""#!/bin/bash
[[ -n ${FAKE_QSTAT:-} ]] || exit 1
printf 'Job Id: %s\n%s\n' "$2" "$FAKE_QSTAT"
"""

# Variables of a real job environment or of the caller that would change what the scripts do.
SCRUB = ("SLURM_", "SBATCH_", "PBS_", "MORPHOGEN_", "FAKE_")
SCRUB_NAMES = {"DECK", "OUT", "EXTRA_ARGS", "ENSEMBLE_FILE", "SWEEP_CHUNKS", "SWEEP_FIRST_INDEX"}


class Cluster:
    """A temporary directory with the fake batch system on PATH and its records."""

    def __init__(self, tmp):
        self.tmp = tmp
        self.bin = tmp / "bin"
        self.state = tmp / "state"
        self.bin.mkdir()
        self.state.mkdir()
        for name, text in (("srun", FAKE_LAUNCHER), ("mpiexec", FAKE_LAUNCHER), ("sbatch", FAKE_SUBMIT),
                           ("qsub", FAKE_SUBMIT), ("squeue", FAKE_SQUEUE), ("scontrol", FAKE_SCONTROL),
                           ("qstat", FAKE_QSTAT)):
            path = self.bin / name
            path.write_text(text)
            path.chmod(0o755)
        self.out = str(tmp / "out")

    def env(self, **extra):
        env = {k: v for k, v in os.environ.items() if not k.startswith(SCRUB) and k not in SCRUB_NAMES}
        env["PATH"] = f"{self.bin}:{env.get('PATH', '/usr/bin:/bin')}"
        env["FAKE_STATE"] = str(self.state)
        env["MORPHOGEN"] = "/bin/true"  # the fake launchers do not run it
        env.update({k: str(v) for k, v in extra.items()})
        return env

    def slurm_env(self, **extra):
        base = dict(SLURM_JOB_ID="1000", SLURM_JOB_NAME="morphogen", SLURM_SUBMIT_DIR=str(self.tmp),
                    SLURM_MEM_PER_CPU="2000", SLURM_CONF="/etc/slurm/slurm.conf", FAKE_SQUEUE="1:00:00",
                    OUT=self.out)
        base.update(extra)
        return self.env(**base)

    def pbs_env(self, **extra):
        base = dict(PBS_JOBID="1000.pbs", PBS_JOBNAME="morphogen", PBS_O_WORKDIR=str(self.tmp),
                    PBS_DEFAULT="pbs", FAKE_QSTAT="    Resource_List.walltime = 02:00:00\n"
                    "    resources_used.walltime = 00:00:30", OUT=self.out)
        base.update(extra)
        return self.env(**base)

    def run(self, script, env, args=(), timeout=30):
        return subprocess.run(["bash", os.path.join(JOBS, script), *args], env=env, cwd=self.tmp,
                              capture_output=True, text=True, timeout=timeout)

    def start(self, script, env, args=()):
        return subprocess.Popen(["bash", os.path.join(JOBS, script), *args], env=env, cwd=self.tmp,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def count(self, what):
        path = self.state / f"{what}.count"
        return int(path.read_text()) if path.exists() else 0

    def launch_args(self, n):
        return (self.state / f"launch.args.{n}").read_text().splitlines()

    def submit_args(self, n):
        return (self.state / f"submit.args.{n}").read_text().splitlines()

    def submit_env(self, n):
        raw = (self.state / f"submit.env.{n}").read_bytes().split(b"\0")
        return dict(item.decode().split("=", 1) for item in raw if b"=" in item)

    def signals(self):
        path = self.state / "launch.signals"
        return path.read_text().split() if path.exists() else []

    def follow(self, n, job_id):
        """Run submission n as the batch system would: its script, arguments and environment."""
        args, env = self.submit_args(n), self.submit_env(n)
        i = next(i for i, a in enumerate(args) if a.endswith((".sbatch", ".pbs")))
        script, script_args, opts = args[i], args[i + 1:], args[:i]
        if script.endswith(".sbatch"):
            env.update(SLURM_JOB_ID=str(job_id), SLURM_JOB_NAME="morphogen", SLURM_SUBMIT_DIR=str(self.tmp))
            for o in opts:
                if o.startswith("--array="):  # a one-index array, as SLURM describes it
                    index = o.split("=", 1)[1]
                    env.update(SLURM_ARRAY_TASK_ID=index, SLURM_ARRAY_TASK_MIN=index, SLURM_ARRAY_TASK_MAX=index,
                               SLURM_ARRAY_TASK_COUNT="1")
        else:
            env.update(PBS_JOBID=f"{job_id}.pbs", PBS_O_WORKDIR=str(self.tmp))
        return subprocess.run(["bash", script, *script_args], env=env, cwd=self.tmp, capture_output=True,
                              text=True, timeout=60)

    def history(self, out=None):
        path = os.path.join(out or self.out, "morphogen_jobs.log")
        return open(path).read() if os.path.exists(path) else ""


@pytest.fixture
def cluster(tmp_path):
    return Cluster(tmp_path)


def wait_for(path, proc, timeout=30):
    """Poll for a file while the process runs."""
    deadline = time.monotonic() + timeout
    while not os.path.exists(path):
        assert proc.poll() is None, f"exited early ({proc.returncode}): {proc.communicate()}"
        assert time.monotonic() < deadline, f"timeout waiting for {path}"
        time.sleep(0.02)


# ---------------------------------------------------------------------------------------------
# (a) shellcheck

def test_all_scripts_present():
    names = {os.path.basename(s) for s in SCRIPTS}
    assert {"run.sbatch", "array.sbatch", "sweep_array.sbatch", "run.pbs", "array.pbs", "sweep_array.pbs",
            "lib_morphogen.sh"} <= names


@pytest.mark.parametrize("script", SCRIPTS, ids=os.path.basename)
def test_shellcheck(script):
    shellcheck = shutil.which("shellcheck")
    if shellcheck is None:
        pytest.skip("shellcheck is not installed")
    res = subprocess.run([shellcheck, "-x", "-s", "bash", script], cwd=SOURCE, capture_output=True, text=True)
    assert res.returncode == 0, res.stdout + res.stderr


# ---------------------------------------------------------------------------------------------
# Library functions

def lib(snippet, **env):
    res = subprocess.run(["bash", "-c", f'source "{JOBS}/lib_morphogen.sh"; {snippet}'], capture_output=True,
                         text=True, timeout=10, env=dict(os.environ, **env))
    return res.returncode, res.stdout.strip()


@pytest.mark.parametrize("text,unit,seconds", [
    ("59:58", 60, 3598), ("1:00:00", 60, 3600), ("  12:00:00 ", 60, 43200), ("2-03:04:05", 60, 183845),
    ("1-0", 60, 86400), ("1-02:30", 60, 95400), ("30", 60, 1800), ("08:09", 60, 489),
    ("3600", 1, 3600), ("01:00:00", 1, 3600), ("10:00", 1, 600), ("00:00:30", 1, 30),
])
def test_duration_seconds(text, unit, seconds):
    assert lib(f'mg_duration_seconds "{text}" {unit}') == (0, str(seconds))


@pytest.mark.parametrize("text", ["UNLIMITED", "NOT_SET", "INVALID", "", "1:2:3:4", "1-2:3:4:5", "abc", "-5"])
def test_duration_seconds_rejects(text):
    assert lib(f'mg_duration_seconds "{text}" 60')[0] != 0


def test_split_and_quote_round_trip():
    """EXTRA_ARGS and member lines are split like a shell would; the log quotes them back."""
    words = ["-seed", "3", "-params_alpha", "12 +- 0.2% gauss", "it's", "a[1]", "", "-grid_n", "64,64"]
    line = r"""-seed 3 -params_alpha "12 +- 0.2% gauss" it\'s a[1] '' -grid_n 64,64"""
    rc, out = lib(r"""mg_split_words w "$LINE"; printf '%s\n' "${w[@]}"; """
                  r"""eval "set -- $(mg_quote "${w[@]}")"; printf '%s\n' "$@" """, LINE=line)
    assert rc == 0
    assert out.split("\n") == words + words


def test_latest_checkpoint(tmp_path):
    for step in (900, 10000, 99999999, 20):
        (tmp_path / f"checkpoint_{step:07d}.vtkhdf").write_text("")
    (tmp_path / "checkpoint_latest.vtkhdf").write_text("")
    assert lib(f'mg_latest_checkpoint "{tmp_path}"') == (0, "checkpoint_99999999.vtkhdf")
    assert lib(f'mg_latest_checkpoint "{tmp_path}/none"') == (0, "")


def test_sweep_points_done(tmp_path):
    """A chunk's progress: its own finished points only (p mod C == c), not other files."""
    points = tmp_path / "points"
    points.mkdir()
    for p in range(10):
        (points / f"point_{p:06d}.json").write_text("{}")
    for name in ("point_000011.json.tmp", "point_000011.vtkhdf", "point_x.json", "sweep.json"):
        (points / name).write_text("")
    count = 'MG_SWEEP_CHUNK={} MG_SWEEP_CHUNKS={}; mg_sweep_points_done "{}"'
    assert lib(count.format(1, 4, tmp_path)) == (0, "3 finished points")  # 1 5 9
    assert lib(count.format(3, 4, tmp_path)) == (0, "2 finished points")  # 3 7
    assert lib(count.format(0, 1, tmp_path)) == (0, "10 finished points")
    assert lib(count.format(10, 11, tmp_path)) == (0, "")
    assert lib(count.format(0, 1, tmp_path / "none")) == (0, "")


# ---------------------------------------------------------------------------------------------
# (b) resubmission logic, SLURM

def test_run_done_is_not_resubmitted(cluster):
    env = cluster.slurm_env(DECK=DECK, EXTRA_ARGS="-steps 500 -png_every 0", FAKE_EXIT_CODES="0")
    res = cluster.run("run.sbatch", env, ["-grid_n", "64,64"])
    assert res.returncode == 0, res.stderr
    assert cluster.launch_args(1) == ["/bin/true", DECK, "-output_dir", cluster.out, "-restart", "latest",
                                      "-max_walltime", "56", "-steps", "500", "-png_every", "0",
                                      "-grid_n", "64,64"]
    assert cluster.count("submit") == 0
    assert "run finished (exit 0)" in cluster.history()


def test_exit_3_resubmits_with_same_arguments_and_environment(cluster):
    args = ["input/turing_stripes.yaml", "-grid_n", "64,64", "-params_alpha", "12 +- 0.2% gauss"]
    os.makedirs(cluster.tmp / "input")
    shutil.copy(os.path.join(SOURCE, "input", "turing_stripes.yaml"), cluster.tmp / "input")
    env = cluster.slurm_env(EXTRA_ARGS='-steps 500 -png_range_a "0,8"', FAKE_EXIT_CODES="3")
    res = cluster.run("run.sbatch", env, args)
    assert res.returncode == 0, res.stderr  # handed over to the resubmitted job
    assert cluster.launch_args(1) == ["/bin/true", "input/turing_stripes.yaml", "-output_dir", cluster.out,
                                      "-restart", "latest", "-max_walltime", "56", "-steps", "500",
                                      "-png_range_a", "0,8", "-grid_n", "64,64", "-params_alpha",
                                      "12 +- 0.2% gauss"]
    assert cluster.count("submit") == 1
    assert cluster.submit_args(1) == ["--export=ALL", "--job-name=morphogen",
                                      os.path.join(JOBS, "run.sbatch"), *args]
    sub = cluster.submit_env(1)
    assert sub["MORPHOGEN_RESUBMIT_COUNT"] == "1"
    assert sub["OUT"] == cluster.out and sub["EXTRA_ARGS"] == env["EXTRA_ARGS"]
    assert sub["MORPHOGEN_JOB_SCRIPT"] == os.path.join(JOBS, "run.sbatch")
    # this job's SLURM_* variables do not leak into the next job (SLURM_CONF does)
    assert "SLURM_JOB_ID" not in sub and "SLURM_MEM_PER_CPU" not in sub
    assert sub["SLURM_CONF"] == "/etc/slurm/slurm.conf"
    assert (cluster.state / "submit.cwd.1").read_text().strip() == str(cluster.tmp)
    assert "resubmitted (1 of at most 10)" in cluster.history()


def test_chain_continues_until_done(cluster):
    env = cluster.slurm_env(FAKE_EXIT_CODES="3 3 0")
    assert cluster.run("run.sbatch", env, ["-steps", "900"]).returncode == 0
    assert cluster.follow(1, 1001).returncode == 0
    res = cluster.follow(2, 1002)
    assert res.returncode == 0, res.stderr
    assert cluster.count("launch") == 3 and cluster.count("submit") == 2
    for n in (1, 2, 3):
        assert cluster.launch_args(n)[1:5] == ["-output_dir", cluster.out, "-restart", "latest"]
        assert cluster.launch_args(n)[-2:] == ["-steps", "900"]
    assert cluster.submit_env(2)["MORPHOGEN_RESUBMIT_COUNT"] == "2"
    log = cluster.history()
    assert "segment 3 of at most 11 starts from checkpoint_0000200.vtkhdf" in log
    assert log.count("resubmitted") == 2 and "run finished" in log


def test_resubmission_cap(cluster):
    env = cluster.slurm_env(FAKE_EXIT_CODES="3", MORPHOGEN_MAX_RESUBMIT="2")
    assert cluster.run("run.sbatch", env).returncode == 0
    assert cluster.follow(1, 1001).returncode == 0
    res = cluster.follow(2, 1002)
    assert res.returncode == 3  # stopped at a checkpoint, not resubmitted
    assert cluster.count("launch") == 3 and cluster.count("submit") == 2
    assert "resubmission cap reached (2 of MORPHOGEN_MAX_RESUBMIT=2)" in res.stderr
    assert "not resubmitted" in cluster.history()


def test_cap_zero_never_resubmits(cluster):
    res = cluster.run("run.sbatch", cluster.slurm_env(FAKE_EXIT_CODES="3", MORPHOGEN_MAX_RESUBMIT="0"))
    assert res.returncode == 3 and cluster.count("submit") == 0


def test_no_new_checkpoint_is_not_resubmitted(cluster):
    env = cluster.slurm_env(FAKE_EXIT_CODES="3", FAKE_CHECKPOINT="0")
    res = cluster.run("run.sbatch", env)
    assert res.returncode == 3 and cluster.count("submit") == 0
    assert "no new checkpoint" in res.stderr
    env["MORPHOGEN_REQUIRE_PROGRESS"] = "0"
    assert cluster.run("run.sbatch", env).returncode == 0
    assert cluster.count("submit") == 1


def test_failed_submission_exits_3(cluster):
    res = cluster.run("run.sbatch", cluster.slurm_env(FAKE_EXIT_CODES="3", FAKE_SUBMIT_RC="1"))
    assert res.returncode == 3
    assert "resubmission failed" in res.stderr


@pytest.mark.parametrize("code", [1, 2, 4, 137])
def test_failures_are_not_resubmitted(cluster, code):
    res = cluster.run("run.sbatch", cluster.slurm_env(FAKE_EXIT_CODES=str(code)))
    assert res.returncode == code
    assert cluster.count("submit") == 0
    assert f"run failed (exit {code}" in cluster.history()


def test_bad_configuration(cluster):
    res = cluster.run("run.sbatch", cluster.slurm_env(DECK="missing.yaml"))
    assert res.returncode == 1 and "DECK=missing.yaml" in res.stderr
    res = cluster.run("run.sbatch", cluster.slurm_env(MORPHOGEN="/nonexistent/morphogen"))
    assert res.returncode == 1 and "no such executable" in res.stderr
    res = cluster.run("run.sbatch", cluster.slurm_env(EXTRA_ARGS='-params_alpha "12'))
    assert res.returncode == 1 and "unbalanced quotes" in res.stderr
    res = cluster.run("run.sbatch", cluster.slurm_env(MORPHOGEN_MAX_WALLTIME="soon"))
    assert res.returncode == 1 and "MORPHOGEN_MAX_WALLTIME" in res.stderr
    assert cluster.count("launch") == 0


def test_output_dir_from_options(cluster):
    env = cluster.slurm_env(FAKE_EXIT_CODES="0")
    del env["OUT"]
    assert cluster.run("run.sbatch", env, ["-output_dir", "mine", "-steps", "5"]).returncode == 0
    assert cluster.launch_args(1)[1:3] == ["-output_dir", "mine"]
    assert os.path.exists(cluster.tmp / "mine" / "morphogen_jobs.log")


@pytest.mark.parametrize("extra,expected", [
    (dict(FAKE_SQUEUE="", FAKE_SCONTROL="RunTime=00:10:00 TimeLimit=02:00:00"), ["-max_walltime", "106"]),
    (dict(FAKE_SQUEUE="1-00:00:00"), ["-max_walltime", "1436"]),
    (dict(FAKE_SQUEUE="UNLIMITED"), []),
    (dict(FAKE_SQUEUE="", FAKE_SCONTROL="RunTime=00:10:00 TimeLimit=UNLIMITED"), []),
    (dict(FAKE_SQUEUE="", FAKE_SCONTROL=""), []),
    (dict(FAKE_SQUEUE="4:59"), []),  # shorter than the margin
    (dict(MORPHOGEN_WALLTIME_MARGIN="600"), ["-max_walltime", "50"]),
    (dict(MORPHOGEN_MAX_WALLTIME="off"), []),
    (dict(MORPHOGEN_MAX_WALLTIME="30"), ["-max_walltime", "30"]),
    (dict(EXTRA_ARGS="-max_walltime 7"), ["-max_walltime", "7"]),  # the user's own, not ours
])
def test_max_walltime(cluster, extra, expected):
    res = cluster.run("run.sbatch", cluster.slurm_env(FAKE_EXIT_CODES="0", **extra))
    assert res.returncode == 0, res.stderr
    args = cluster.launch_args(1)
    got = [] if "-max_walltime" not in args else args[args.index("-max_walltime"):][:2]
    assert got == expected
    assert args.count("-max_walltime") <= 1


# ---------------------------------------------------------------------------------------------
# (c) signals: the batch shell forwards them to the run and acts on its exit code

@pytest.mark.parametrize("sig,code,resubmit_on_term,rc,submits", [
    (signal.SIGUSR1, 3, "0", 0, 1),  # --signal=B:USR1@...: checkpoint, resubmit
    (signal.SIGUSR1, 0, "0", 0, 0),  # the run finished anyway
    (signal.SIGUSR1, 1, "0", 1, 0),  # the run failed
    (signal.SIGTERM, 3, "0", 3, 0),  # scancel: checkpoint, end of the chain
    (signal.SIGTERM, 3, "1", 0, 1),  # preemption with MORPHOGEN_RESUBMIT_ON_TERM=1
])
def test_signal_forwarded(cluster, sig, code, resubmit_on_term, rc, submits):
    env = cluster.slurm_env(FAKE_EXIT_CODES=str(code), FAKE_WAIT_SIGNAL="1",
                            MORPHOGEN_RESUBMIT_ON_TERM=resubmit_on_term)
    proc = cluster.start("run.sbatch", env, ["-steps", "100"])
    rc_got, err = send_signal_when_ready(cluster, proc, sig)
    # srun gets SIGUSR1 whatever arrived: srun answers SIGTERM by killing the step
    assert cluster.signals() == ["USR1"], err
    assert rc_got == rc, err
    assert cluster.count("submit") == submits
    if submits:
        assert cluster.submit_args(1)[-3:] == [os.path.join(JOBS, "run.sbatch"), "-steps", "100"]


@pytest.mark.parametrize("sig,rc,submits", [(signal.SIGUSR1, 0, 1), (signal.SIGTERM, 3, 0)])
def test_signal_forwarded_pbs(cluster, sig, rc, submits):
    """qsig -s USR1 / qdel on PBS: the same forwarding, to mpiexec."""
    env = cluster.pbs_env(FAKE_EXIT_CODES="3", FAKE_WAIT_SIGNAL="1", PBS_ARRAY_INDEX="4")
    proc = cluster.start("array.pbs", env)
    rc_got, err = send_signal_when_ready(cluster, proc, sig)
    assert cluster.signals() == ["USR1"], err
    assert rc_got == rc, err
    assert cluster.count("submit") == submits


def send_signal_when_ready(cluster, proc, sig):
    """Send a signal to the batch shell once its run is up; returns (exit code, stderr)."""
    try:
        wait_for(cluster.state / "launch.ready", proc)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    return proc.returncode, err


def test_repeated_signals_wait_for_the_real_exit_code(cluster):
    """Each signal interrupts `wait`; the script must keep waiting for the run's own exit."""
    env = cluster.slurm_env(FAKE_EXIT_CODES="3", FAKE_WAIT_SIGNAL="1", FAKE_SIGNALS_NEEDED="3")
    proc = cluster.start("run.sbatch", env)
    try:
        wait_for(cluster.state / "launch.ready", proc)
        for k in range(1, 4):
            proc.send_signal(signal.SIGUSR1)
            deadline = time.monotonic() + 20
            while len(cluster.signals()) < k:
                assert time.monotonic() < deadline
                time.sleep(0.02)
            if k < 3:
                assert proc.poll() is None
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert cluster.signals() == ["USR1"] * 3
    assert proc.returncode == 0, err
    assert cluster.count("submit") == 1


# ---------------------------------------------------------------------------------------------
# Arrays and PBS

def test_array_sbatch_member_from_ensemble_file(cluster):
    env = cluster.slurm_env(SLURM_ARRAY_TASK_ID="3", ENSEMBLE_FILE=os.path.join(JOBS, "ensemble_example.txt"),
                            FAKE_EXIT_CODES="3 0")
    res = cluster.run("array.sbatch", env, [DECK])
    assert res.returncode == 0, res.stderr
    member_out = os.path.join(cluster.out, "member_0003")
    args = cluster.launch_args(1)
    assert args[:6] == ["/bin/true", DECK, "-output_dir", member_out, "-restart", "latest"]
    assert args[-4:] == ["-seed", "3", "-params_alpha", "12 +- 0.2% gauss"]
    # only this index is resubmitted
    assert cluster.submit_args(1) == ["--export=ALL", "--job-name=morphogen", "--array=3",
                                      os.path.join(JOBS, "array.sbatch"), DECK]
    assert cluster.follow(1, 1001).returncode == 0
    assert cluster.launch_args(2) == args
    assert cluster.count("submit") == 1
    assert "resubmitted" in cluster.history(member_out) and "finished" in cluster.history(member_out)


def test_array_sbatch_seed_members(cluster):
    env = cluster.slurm_env(SLURM_ARRAY_TASK_ID="7", FAKE_EXIT_CODES="0")
    assert cluster.run("array.sbatch", env).returncode == 0
    args = cluster.launch_args(1)
    assert args[1:3] == ["-output_dir", os.path.join(cluster.out, "member_0007")]
    assert args[-2:] == ["-seed", "7"]


def test_array_index_out_of_range(cluster):
    env = cluster.slurm_env(SLURM_ARRAY_TASK_ID="5", ENSEMBLE_FILE=os.path.join(JOBS, "ensemble_example.txt"))
    res = cluster.run("array.sbatch", env)
    assert res.returncode == 1 and "has 4 member lines" in res.stderr
    res = cluster.run("array.sbatch", cluster.slurm_env())
    assert res.returncode == 1 and "not an array task" in res.stderr
    assert cluster.count("launch") == 0


def test_run_pbs(cluster):
    env = cluster.pbs_env(DECK=DECK, EXTRA_ARGS="-steps 500", FAKE_EXIT_CODES="3 0")
    res = cluster.run("run.pbs", env)
    assert res.returncode == 0, res.stderr
    # walltime 2 h, 30 s used, 240 s margin
    assert cluster.launch_args(1) == ["/bin/true", DECK, "-output_dir", cluster.out, "-restart", "latest",
                                      "-max_walltime", "115", "-steps", "500"]
    assert cluster.submit_args(1) == ["-V", "-N", "morphogen", os.path.join(JOBS, "run.pbs")]
    sub = cluster.submit_env(1)
    assert sub["MORPHOGEN_RESUBMIT_COUNT"] == "1" and sub["DECK"] == DECK
    assert "PBS_JOBID" not in sub and sub["PBS_DEFAULT"] == "pbs"
    assert cluster.follow(1, 1001).returncode == 0
    assert cluster.count("launch") == 2 and cluster.count("submit") == 1


def test_run_pbs_torque_walltime_and_no_arguments(cluster):
    env = cluster.pbs_env(FAKE_QSTAT="", PBS_WALLTIME="3600", FAKE_EXIT_CODES="0")
    assert cluster.run("run.pbs", env).returncode == 0
    assert cluster.launch_args(1)[-2:] == ["-max_walltime", "56"]
    res = cluster.run("run.pbs", env, ["-steps", "5"])
    assert res.returncode == 1 and "no arguments" in res.stderr


def test_array_pbs_member_resubmitted_as_single_job(cluster):
    env = cluster.pbs_env(PBS_ARRAY_INDEX="2", ENSEMBLE_FILE=os.path.join(JOBS, "ensemble_example.txt"),
                          FAKE_EXIT_CODES="3 3 0")
    assert cluster.run("array.pbs", env).returncode == 0
    member_out = os.path.join(cluster.out, "member_0002")
    assert cluster.launch_args(1)[1:3] == ["-output_dir", member_out]
    assert cluster.launch_args(1)[-2:] == ["-seed", "2"]
    assert cluster.submit_args(1) == ["-V", "-N", "morphogen", os.path.join(JOBS, "array.pbs")]
    sub = cluster.submit_env(1)
    assert sub["MORPHOGEN_ARRAY_INDEX"] == "2" and "PBS_ARRAY_INDEX" not in sub
    assert cluster.follow(1, 1001).returncode == 0
    assert cluster.follow(2, 1002).returncode == 0
    assert [cluster.launch_args(n) for n in (2, 3)] == [cluster.launch_args(1)] * 2
    assert cluster.count("submit") == 2


# ---------------------------------------------------------------------------------------------
# Sweeps in chunks (sweep_array.sbatch, sweep_array.pbs)

def sweep_env(cluster, index, first=0, last=3, **extra):
    """The environment of SLURM array task INDEX of --array=FIRST-LAST."""
    return cluster.slurm_env(SLURM_ARRAY_TASK_ID=str(index), SLURM_ARRAY_TASK_MIN=str(first),
                             SLURM_ARRAY_TASK_MAX=str(last), SLURM_ARRAY_TASK_COUNT=str(last - first + 1),
                             SLURM_ARRAY_TASK_STEP="1", SLURM_ARRAY_JOB_ID="999", **extra)


@pytest.mark.parametrize("index,first,last,chunk,chunks", [
    (0, 0, 3, 0, 4), (2, 0, 3, 2, 4), (3, 0, 3, 3, 4),  # --array=0-3
    (1, 1, 8, 0, 8), (8, 1, 8, 7, 8),  # --array=1-8: the offset is the first index
    (0, 0, 0, 0, 1),  # --array=0: the whole sweep in one task
])
def test_sweep_array_chunk_command_line(cluster, index, first, last, chunk, chunks):
    env = sweep_env(cluster, index, first, last, EXTRA_ARGS='-grid_n 32,32 -sweep_params_F "linspace(0.01, 0.07, 4)"',
                    FAKE_EXIT_CODES="0")
    res = cluster.run("sweep_array.sbatch", env, [DECK, "-steps", "500"])
    assert res.returncode == 0, res.stderr
    # one output directory for all chunks (no member_NNNN)
    assert cluster.launch_args(1) == ["/bin/true", "sweep", DECK, "-output_dir", cluster.out,
                                      "-sweep_chunk", str(chunk), "-sweep_chunks", str(chunks),
                                      "-restart", "latest", "-max_walltime", "56", "-grid_n", "32,32",
                                      "-sweep_params_F", "linspace(0.01, 0.07, 4)", "-steps", "500"]
    assert cluster.count("submit") == 0
    assert "run finished (exit 0)" in cluster.history()


@pytest.mark.parametrize("extra,index,chunk,chunks", [
    (dict(SWEEP_CHUNKS="8"), 5, 5, 8),  # e.g. SWEEP_CHUNKS=8 sbatch --array=3,5: index i is chunk i
    (dict(SWEEP_CHUNKS="8", SWEEP_FIRST_INDEX="2"), 5, 3, 8),
    (dict(SWEEP_FIRST_INDEX="3"), 5, 2, 4),  # size from the array, offset given
])
def test_sweep_array_chunks_from_environment(cluster, extra, index, chunk, chunks):
    env = sweep_env(cluster, index, 3, 6, FAKE_EXIT_CODES="0", **extra)
    res = cluster.run("sweep_array.sbatch", env, [DECK])
    assert res.returncode == 0, res.stderr
    assert cluster.launch_args(1)[5:9] == ["-sweep_chunk", str(chunk), "-sweep_chunks", str(chunks)]


@pytest.mark.parametrize("extra,args,message", [
    (dict(SLURM_ARRAY_TASK_ID="4", SLURM_ARRAY_TASK_MAX="14", SLURM_ARRAY_TASK_COUNT="8",
          SLURM_ARRAY_TASK_STEP="2"), [DECK], "not contiguous"),  # --array=0-14:2
    (dict(SLURM_ARRAY_TASK_ID="5", SLURM_ARRAY_TASK_MAX="9", SLURM_ARRAY_TASK_COUNT="3",
          SLURM_ARRAY_TASK_STEP=""), [DECK], "not contiguous"),  # --array=1,5,9
    (dict(SLURM_ARRAY_TASK_ID="4", SLURM_ARRAY_TASK_MAX="14", SLURM_ARRAY_TASK_COUNT="",
          SLURM_ARRAY_TASK_STEP="2"), [DECK], "not contiguous"),  # no count: the step tells
    (dict(SLURM_ARRAY_TASK_ID="5", SLURM_ARRAY_TASK_MIN="", SLURM_ARRAY_TASK_MAX="",
          SLURM_ARRAY_TASK_COUNT=""), [DECK], "index range is unknown"),
    (dict(SLURM_ARRAY_TASK_ID="5", SWEEP_CHUNKS="4"), [DECK], "chunk 5 is not in 0..3"),
    (dict(SWEEP_CHUNKS="0"), [DECK], "SWEEP_CHUNKS=0"),
    (dict(SLURM_ARRAY_TASK_ID=""), [DECK], "not an array task"),
    ({}, ["-steps", "5"], "a sweep needs a deck"),
    ({}, [DECK, "-sweep_chunk", "1"], "-sweep_chunk: the chunks are the array tasks"),
    (dict(EXTRA_ARGS="-sweep_chunks 3"), [DECK], "-sweep_chunks: the chunks are the array tasks"),
])
def test_sweep_array_bad_configuration(cluster, extra, args, message):
    env = sweep_env(cluster, 1, 0, 3)
    env.update(extra)
    res = cluster.run("sweep_array.sbatch", {k: v for k, v in env.items() if v != ""}, args)
    assert res.returncode == 1 and message in res.stderr, res.stderr
    assert cluster.count("launch") == 0


def test_sweep_array_resubmits_its_chunk_while_it_finishes_points(cluster):
    """Exit 3 -> resubmission of that index only, as long as the chunk finished more of its own
    points; a checkpoint or another chunk's points are not progress."""
    # --array=1-4: task 3 is chunk 2 of 4 (points 2, 6, 10, ...). Call 1 finishes points 2 and
    # 3 (the latter another chunk's), call 2 point 6, call 3 only point 7 (another chunk's).
    env = sweep_env(cluster, 3, 1, 4, FAKE_EXIT_CODES="3", FAKE_POINTS="2 3;6;7")
    res = cluster.run("sweep_array.sbatch", env, [DECK])
    assert res.returncode == 0, res.stderr  # handed over to the resubmitted job
    args = cluster.launch_args(1)
    assert args[:9] == ["/bin/true", "sweep", DECK, "-output_dir", cluster.out, "-sweep_chunk", "2",
                        "-sweep_chunks", "4"]
    assert cluster.submit_args(1) == ["--export=ALL", "--job-name=morphogen", "--array=3",
                                      os.path.join(JOBS, "sweep_array.sbatch"), DECK]
    sub = cluster.submit_env(1)
    assert (sub["SWEEP_CHUNKS"], sub["SWEEP_FIRST_INDEX"], sub["MORPHOGEN_RESUBMIT_COUNT"]) == ("4", "1", "1")
    assert not any(k.startswith("SLURM_ARRAY") for k in sub)
    # the resubmitted job is a one-index array (3-3): still chunk 2 of 4
    res = cluster.follow(1, 1001)
    assert res.returncode == 0, res.stderr
    assert cluster.launch_args(2) == args and cluster.count("submit") == 2
    res = cluster.follow(2, 1002)
    assert res.returncode == 3, res.stderr
    assert cluster.launch_args(3) == args and cluster.count("submit") == 2
    assert "no new finished point of chunk 2/4" in res.stderr
    assert "(before: 2 finished points, now: 2 finished points)" in res.stderr
    log = cluster.history()
    assert "segment 1 of at most 11 starts: srun /bin/true sweep" in log
    assert "segment 3 of at most 11 starts from 2 finished points: " in log
    assert log.count("resubmitted (") == 2 and "not resubmitted" in log


def test_sweep_array_no_points_no_resubmission(cluster):
    env = sweep_env(cluster, 0, FAKE_EXIT_CODES="3")  # leaves a checkpoint, no point
    res = cluster.run("sweep_array.sbatch", env, [DECK])
    assert res.returncode == 3 and cluster.count("submit") == 0
    assert "no new finished point of chunk 0/4 in " in res.stderr
    env["MORPHOGEN_REQUIRE_PROGRESS"] = "0"
    assert cluster.run("sweep_array.sbatch", env, [DECK]).returncode == 0
    assert cluster.count("submit") == 1


def test_sweep_array_signal_forwarded(cluster):
    """--signal=B:USR1@...: the sweep gets SIGUSR1, stops with exit 3 after finishing a point."""
    env = sweep_env(cluster, 1, FAKE_EXIT_CODES="3", FAKE_WAIT_SIGNAL="1", FAKE_POINTS="1")
    proc = cluster.start("sweep_array.sbatch", env, [DECK])
    rc, err = send_signal_when_ready(cluster, proc, signal.SIGUSR1)
    assert cluster.signals() == ["USR1"], err
    assert rc == 0 and cluster.count("submit") == 1, err


def test_sweep_array_pbs(cluster):
    """PBS Pro qsub -J 0-2: the range from qstat -f; the chunk comes back as a plain job."""
    qstat = ("    Resource_List.walltime = 02:00:00\n    resources_used.walltime = 00:00:30\n"
             "    array = True\n    array_indices_submitted = 0-2\n")
    env = cluster.pbs_env(DECK=DECK, PBS_ARRAY_INDEX="1", PBS_ARRAY_ID="1000[].pbs", FAKE_QSTAT=qstat,
                          EXTRA_ARGS="-steps 500", FAKE_EXIT_CODES="3 0", FAKE_POINTS="1 2")
    res = cluster.run("sweep_array.pbs", env)
    assert res.returncode == 0, res.stderr
    args = cluster.launch_args(1)
    assert args == ["/bin/true", "sweep", DECK, "-output_dir", cluster.out, "-sweep_chunk", "1",
                    "-sweep_chunks", "3", "-restart", "latest", "-max_walltime", "115", "-steps", "500"]
    assert cluster.submit_args(1) == ["-V", "-N", "morphogen", os.path.join(JOBS, "sweep_array.pbs")]
    sub = cluster.submit_env(1)
    assert (sub["MORPHOGEN_ARRAY_INDEX"], sub["SWEEP_CHUNKS"], sub["SWEEP_FIRST_INDEX"]) == ("1", "3", "0")
    assert "PBS_ARRAY_INDEX" not in sub and "PBS_ARRAY_ID" not in sub
    assert cluster.follow(1, 1001).returncode == 0
    assert cluster.launch_args(2) == args and cluster.count("submit") == 1


def test_sweep_array_pbs_torque_needs_sweep_chunks(cluster):
    env = cluster.pbs_env(DECK=DECK, PBS_ARRAYID="1", FAKE_EXIT_CODES="0")  # qsub -t: no range known
    res = cluster.run("sweep_array.pbs", env)
    assert res.returncode == 1 and "set SWEEP_CHUNKS" in res.stderr
    env["SWEEP_CHUNKS"] = "2"
    assert cluster.run("sweep_array.pbs", env).returncode == 0
    assert cluster.launch_args(1)[5:9] == ["-sweep_chunk", "1", "-sweep_chunks", "2"]


# ---------------------------------------------------------------------------------------------
# The real binary: SIGUSR1 -> checkpoint, exit 3 -> resubmission -> restart -> done

def send_usr1_when(proc, ready, timeout, ended, missing):
    """Poll ready() every 50 ms while the batch shell runs (pytest.fail "<ended> (rc): output" if
    it ends first; assert "<missing> within <timeout> s" past timeout), then send it SIGUSR1 and
    let it finish; returns (stdout, stderr). Kills the shell if it is still running on the way out."""
    try:
        deadline = time.monotonic() + timeout
        while not ready():
            if proc.poll() is not None:
                pytest.fail(f"{ended} ({proc.returncode}): {proc.communicate()}")
            assert time.monotonic() < deadline, f"{missing} within {timeout} s"
            time.sleep(0.05)
        proc.send_signal(signal.SIGUSR1)
        return proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()


def test_real_morphogen_signal_checkpoint_restart(cluster):
    out = cluster.out
    steps = 60000
    env = cluster.slurm_env(
        MORPHOGEN=EXE, MORPHOGEN_LAUNCHER=f"{MPIEXEC} --oversubscribe -n 2",
        EXTRA_ARGS=f"-grid_n 16,16 -steps {steps} -checkpoint_every 1000 -png_every 0",
        OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_rmaps_base_oversubscribe="1")
    proc = cluster.start("run.sbatch", env)
    stdout, err = send_usr1_when(proc, lambda: glob.glob(os.path.join(out, "checkpoint_*.vtkhdf")), 60,
                                 "run ended before its first checkpoint", "no checkpoint")
    assert proc.returncode == 0, stdout + err  # exit 3, resubmitted
    assert cluster.count("submit") == 1
    first = sorted(glob.glob(os.path.join(out, "checkpoint_*.vtkhdf")))[-1]
    assert not os.path.exists(os.path.join(out, "a_final.png"))
    res = cluster.follow(1, 1001)  # the resubmitted job restarts from the checkpoint
    assert res.returncode == 0, res.stdout + res.stderr
    assert cluster.count("submit") == 1
    assert os.path.exists(os.path.join(out, "a_final.png"))
    log = cluster.history()
    assert f"starts from {os.path.basename(first)}" in log and "run finished (exit 0)" in log


# The real binary as a sweep: a fake srun that records its arguments and runs the rest on one rank.
REAL_SRUN = r"""#!/bin/bash
n=$(( $(cat "$FAKE_STATE/launch.count" 2>/dev/null || echo 0) + 1 ))
echo "$n" > "$FAKE_STATE/launch.count"
printf '%s\n' "$@" > "$FAKE_STATE/launch.args.$n"
exec "$REAL_MPIEXEC" --oversubscribe -n 1 "$@"
"""

TINY_SWEEP = ("-grid_n 16,16 -grid_L 0.15625 -steps 200 -sweep_params_F 0.03,0.04 "
              "-sweep_params_k 0.06,0.065")


def real_sweep_env(cluster, index, last, extra_args):
    (cluster.bin / "srun").write_text(REAL_SRUN)
    return sweep_env(cluster, index, 0, last, MORPHOGEN=EXE, REAL_MPIEXEC=MPIEXEC, EXTRA_ARGS=extra_args,
                     OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                     OMPI_MCA_rmaps_base_oversubscribe="1")


def finished_points(out):
    return sorted(os.path.basename(f) for f in glob.glob(os.path.join(out, "points", "point_*.json")))


def test_real_sweep_two_chunks_finish_all_points(cluster):
    """Array --array=0-1 on a 2 x 2 sweep: each task runs its chunk, together all 4 points."""
    sweep_deck = os.path.join(SOURCE, "input", "gray_scott_sweep.yaml")
    for index, points in ((0, ["point_000000.json", "point_000002.json"]), (1, ["point_000001.json",
                                                                              "point_000003.json"])):
        res = cluster.run("sweep_array.sbatch", real_sweep_env(cluster, index, 1, TINY_SWEEP), [sweep_deck],
                          timeout=120)
        assert res.returncode == 0, res.stdout + res.stderr
        assert f"chunk {index}/2: 2 to run, " in res.stdout
        assert cluster.launch_args(index + 1)[5:11] == ["-sweep_chunk", str(index), "-sweep_chunks", "2",
                                                         "-restart", "latest"]
        assert set(points) <= set(finished_points(cluster.out))
    assert finished_points(cluster.out) == [f"point_{p:06d}.json" for p in range(4)]
    with open(os.path.join(cluster.out, "sweep.csv")) as f:
        assert len(f.read().strip().splitlines()) == 1 + 4  # header, one row per point
    assert cluster.count("submit") == 0
    assert cluster.history().count("run finished (exit 0)") == 2
    # a chunk that is done stays done
    res = cluster.run("sweep_array.sbatch", real_sweep_env(cluster, 0, 1, TINY_SWEEP), [sweep_deck], timeout=120)
    assert res.returncode == 0 and "chunk 0/2: 0 to run, 4 already done" in res.stdout, res.stdout + res.stderr


def test_real_sweep_signal_resubmit_resume(cluster):
    """SIGUSR1 to the batch shell while chunk 0 of 2 runs its second point (about a second each):
    that point is abandoned, exit 3 with one point more -> resubmission -> the resubmitted job
    runs only the remaining point."""
    sweep_deck = os.path.join(SOURCE, "input", "gray_scott_sweep.yaml")
    slow = "-grid_n 64,64 -steps 50000 -sweep_params_F 0.03,0.04 -sweep_params_k 0.06,0.065"
    proc = cluster.start("sweep_array.sbatch", real_sweep_env(cluster, 0, 1, slow), [sweep_deck])
    stdout, err = send_usr1_when(proc, lambda: finished_points(cluster.out), 120,
                                 "sweep ended before its first point", "no finished point")
    assert proc.returncode == 0, stdout + err  # exit 3 with progress: resubmitted
    assert "stopped by a signal" in stdout + err
    assert finished_points(cluster.out) == ["point_000000.json"]
    assert cluster.count("submit") == 1 and "--array=0" in cluster.submit_args(1)
    res = cluster.follow(1, 1001)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "chunk 0/2: 1 to run, 1 already done" in res.stdout
    assert finished_points(cluster.out) == ["point_000000.json", "point_000002.json"]
    assert cluster.count("submit") == 1
    log = cluster.history()
    assert "starts from 1 finished points" in log and "run finished (exit 0)" in log


# ---------------------------------------------------------------------------------------------
# The exit code as seen through the launcher, and the launcher's environment


@pytest.mark.parametrize("script,env_of", [("run.sbatch", "slurm_env"), ("run.pbs", "pbs_env")])
def test_ranks_exit_code_wins_over_the_launchers(cluster, script, env_of):
    """Open MPI's mpiexec returns 1 when SIGTERM reached it although the ranks checkpointed and
    exited 3: the exit code the ranks wrote (MORPHOGEN_EXIT_FILE) decides, so the job resubmits."""
    env = getattr(cluster, env_of)(FAKE_EXIT_CODES="1", FAKE_RANKS_EXIT="3")
    res = cluster.run(script, env)
    assert res.returncode == 0, res.stderr  # exit 3 with a new checkpoint: resubmitted
    assert cluster.count("submit") == 1
    assert "the launcher returned 1, the ranks exited with 3: using 3" in res.stderr
    assert not os.path.exists(os.path.join(cluster.out, ".morphogen_exit_code"))


def test_no_exit_file_keeps_the_launchers_code(cluster):
    """An aborted run writes no exit file: the launcher's code stands (and a stale file from an
    earlier segment is removed before the launch)."""
    os.makedirs(cluster.out)
    with open(os.path.join(cluster.out, ".morphogen_exit_code"), "w") as f:
        f.write("3\n")
    res = cluster.run("run.sbatch", cluster.slurm_env(FAKE_EXIT_CODES="4"))
    assert res.returncode == 4, res.stderr
    assert cluster.count("submit") == 0


def test_launcher_environment_keeps_signals_deliverable(cluster):
    """hwloc's OpenCL/GL plugins are off (an OpenCL ICD's LLVM would take SIGUSR1 from mpiexec),
    mpiexec gives the ranks time to checkpoint on SIGTERM; a user's own settings are kept."""
    cluster.run("run.pbs", cluster.pbs_env())
    assert (cluster.state / "launch.env.1").read_text().split() == ["-opencl,-gl", "30"]
    cluster.run("run.pbs", cluster.pbs_env(HWLOC_COMPONENTS="-cuda", OMPI_MCA_odls_base_sigkill_timeout="5"))
    assert (cluster.state / "launch.env.2").read_text().split() == ["-cuda", "5"]


def test_real_mpiexec_sigterm_exit_code_through_the_job(cluster):
    """The batch system's SIGTERM to the whole job (shell, mpiexec and ranks): the ranks
    checkpoint and exit 3, mpiexec returns its own code, the job reads the ranks' code and (with
    MORPHOGEN_RESUBMIT_ON_TERM=1) resubmits; the checkpoint is complete."""
    out = cluster.out
    env = cluster.pbs_env(
        MORPHOGEN=EXE, MORPHOGEN_LAUNCHER=f"{MPIEXEC} --oversubscribe -n 2", MORPHOGEN_RESUBMIT_ON_TERM="1",
        OMPI_MCA_odls_base_sigkill_timeout="10",
        EXTRA_ARGS="-grid_n 32,32 -steps 10000000 -png_every 0 -progress_every 1000000",
        OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_rmaps_base_oversubscribe="1")
    proc = subprocess.Popen(["bash", os.path.join(JOBS, "run.pbs")], env=env, cwd=cluster.tmp,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while not os.path.exists(os.path.join(out, "options_used.yaml.tmp")) and \
                not os.path.exists(os.path.join(out, "options_used.yaml")):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the run did not start"
            time.sleep(0.05)
        time.sleep(1.0)
        os.killpg(proc.pid, signal.SIGTERM)  # every process of the job, as qdel / a preemption does
        stdout, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 0, stdout + err  # resubmitted
    assert cluster.count("submit") == 1, err
    checkpoints = glob.glob(os.path.join(out, "checkpoint_*.vtkhdf"))
    assert len(checkpoints) == 1 and not glob.glob(os.path.join(out, "*.tmp")), os.listdir(out)
