"""Studies through executors, on real ODE: the same numbers in this process, in a local process pool and on a real
(local) Dask cluster; results in task order whatever order they finish in; an executor that cannot be had refused in
one line; parameter grids from the command line, one row per combination."""

import concurrent.futures
import json
import subprocess
import sys
import threading
import time

import pytest

from steadystep import SteadystepError
from steadystep.lab import probe, runs, study
from test_cli import steadystep

# The issue's command (with the policies at hand on every scene).
ISSUE_COMPARE = ["--scenes", "oscillator", "chain", "--profiles", "fixed:30", "uniform:15:45",
                 "--policies", "naive", "implicit-euler", "--duration", "1"]


def _numbers(metrics: dict) -> dict:
    """Everything in metrics.json that is measured motion, not timing."""
    return {"rows": [(r["scene"], r["profile"], r["policy"], r["status"], r["deviation"], r["rms_vs_exact"],
                      r["steps_per_frame"]) for r in metrics["rows"]],
            "spread": metrics["spread"], "side_by_side": metrics["oscillator_side_by_side"],
            "probes": metrics["largest_stable_step"]}


def test_compare_gives_the_same_numbers_in_this_process_a_local_pool_and_on_dask(tmp_path):
    found = {}
    for executor in ("serial", "local", "dask"):
        result = steadystep("compare", "--out", tmp_path / executor, *ISSUE_COMPARE, "--executor", executor)
        assert result.returncode == 0, result.stderr
        found[executor] = _numbers(json.loads((tmp_path / executor / "metrics.json").read_text()))
    assert len(found["serial"]["rows"]) == 2 * 2 * 2
    # Bit for bit: JSON keeps every double's 17 digits.
    assert found["serial"] == found["local"] == found["dask"]


def test_an_unreachable_scheduler_is_one_line_and_exit_2(tmp_path):
    result = steadystep("compare", "--out", tmp_path / "out", *ISSUE_COMPARE, "--executor", "dask:tcp://127.0.0.1:9")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert "tcp://127.0.0.1:9" in result.stderr and "scheduler" in result.stderr
    assert not (tmp_path / "out").exists()  # refused before anything was written


def test_without_dask_the_dask_executor_names_the_extra():
    blocked = ("import sys; sys.modules['distributed'] = None; from steadystep.cli import main; "
               "sys.exit(main(['probe', 'oscillator', '--executor', 'dask']))")
    result = subprocess.run([sys.executable, "-c", blocked], capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert "pip install 'steadystep[dask]'" in result.stderr


@pytest.mark.parametrize("spec", ["", "threads", "dask:", "local:4", "DASK"])
def test_an_unknown_executor_is_refused_naming_it(spec):
    with pytest.raises(study.ExecutorUnavailable, match="executor = "):
        with study.make_executor(spec):
            pass


def test_importing_the_package_imports_no_dask():
    code = ("import sys, steadystep, steadystep.lab.study, steadystep.report, steadystep.lab.probe, steadystep.cli; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stdout.strip() == "[]", result.stderr


TASKS = study.grid(scene=["oscillator", "chain"], profile=["fixed:30", "uniform:15:45"],
                   policy=["naive", "implicit-euler"], duration_s=[1.0])


def _same_runs(a: list[runs.RunResult], b: list[runs.RunResult]) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert (x.scene, x.profile, x.policy, x.status) == (y.scene, y.profile, y.policy, y.status)
        assert x.times.tobytes() == y.times.tobytes()
        assert all(x.quantities[q].tobytes() == y.quantities[q].tobytes() for q in x.quantities)


def test_sweep_through_any_executor_equals_the_serial_sweep():
    serial = study.sweep(runs.run, TASKS)
    assert [(r.scene, r.profile, r.policy) for r in serial] == [(t["scene"], t["profile"], t["policy"]) for t in TASKS]
    # One thread: ODE's random seed (quickstep's constraint order) is one per process, so two scenes must not step
    # in one process at once.
    with concurrent.futures.ThreadPoolExecutor(max_workers=1) as threads:
        _same_runs(serial, study.sweep(runs.run, TASKS, threads))
    _same_runs(serial, study.sweep(runs.run, TASKS, "local"))


def _after(value: int, delay_s: float, finished: list, lock: threading.Lock) -> int:
    time.sleep(delay_s)
    with lock:
        finished.append(value)
    return value * value


def test_results_come_in_task_order_whatever_order_they_finish_in():
    finished, lock = [], threading.Lock()
    tasks = [dict(value=i, delay_s=0.05 * (5 - i), finished=finished, lock=lock) for i in range(6)]
    with concurrent.futures.ThreadPoolExecutor(max_workers=6) as threads:
        assert study.sweep(_after, tasks, threads) == [i * i for i in range(6)]
    assert sorted(finished) == list(range(6))


def test_a_failing_unit_raises_its_refusal_through_a_process_pool():
    tasks = [dict(scene="oscillator", profile="fixed:30", policy="naive", duration_s=0.5),
             dict(scene="oscillator", profile="fixed:0", policy="naive", duration_s=0.5)]
    with pytest.raises(SteadystepError, match="fixed:0") as refused:
        study.sweep(runs.run, tasks, "local")
    assert refused.value.status  # status, message and code survive the trip between processes


def test_grid_is_every_combination_last_axis_fastest():
    assert study.grid() == [{}]
    assert study.grid(k=[1, 2], c=[0.5, 1]) == [{"k": 1, "c": 0.5}, {"k": 1, "c": 1}, {"k": 2, "c": 0.5},
                                                {"k": 2, "c": 1}]
    assert study.grid(k=[1, 2], c=[]) == []


def test_probe_by_policy_is_the_same_through_a_pool():
    policies = ["naive", "implicit-euler"]
    serial = probe.largest_stable_steps("chain", policies, duration_s=1.0)
    assert serial == [probe.largest_stable_step("chain", p, duration_s=1.0) for p in policies]
    assert probe.largest_stable_steps("chain", policies, duration_s=1.0, executor="local") == serial


def test_grid_flags_give_one_row_per_combination(tmp_path):
    result = steadystep("compare", "--out", tmp_path, "--scenes", "oscillator", "--profiles", "fixed:30",
                        "--policies", "implicit-euler", "--duration", "1", "--stiffness", "20", "80",
                        "--damping", "0.5", "2", "--max-step", "1/60", "1/30", "--executor", "serial")
    assert result.returncode == 0, result.stderr
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    grids = [r["grid"] for r in metrics["rows"]]
    assert grids == [{"stiffness": k, "damping": c, "max_step_s": h}
                     for k in (20.0, 80.0) for c in (0.5, 2.0) for h in (1 / 60, 1 / 30)]
    mass = metrics["params"]["oscillator"]["mass"]
    for row in metrics["rows"]:
        # 30 fps frames cut into steps of at most max_step_s: 2 steps of 1/60 s, 1 of 1/30 s.
        assert row["steps_per_frame"] == round((1 / 30) / row["grid"]["max_step_s"])
    # The exact solution's decay rate, c / 2m, follows each row's damping: the grid reached the scene.
    side = metrics["oscillator_side_by_side"]
    assert {(e["grid"]["damping"], e["true_decay_rate_per_s"]) for e in side} == {(0.5, 0.5 / (2 * mass)),
                                                                                  (2.0, 2.0 / (2 * mass))}
    header = (tmp_path / "metrics.csv").read_text().splitlines()[0]
    assert header.startswith("scene,profile,policy,stiffness_N_per_m,damping_N_s_per_m,max_step_s,quantity")


@pytest.mark.parametrize("args", [["--stiffness", "nan"], ["--max-step", "1/0"], ["--max-step", "0"],
                                  ["--stiffness", "-5"], ["--damping", "x"]])
def test_bad_grid_values_exit_2_with_one_line(tmp_path, args):
    result = steadystep("compare", "--out", tmp_path / "out", "--scenes", "oscillator", "--profiles", "fixed:30",
                        "--duration", "1", *args)
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert not (tmp_path / "out").exists()


def _imported(name: str) -> bool:
    import sys

    return name in sys.modules


def test_the_local_pools_workers_start_with_the_study_modules_already_imported():
    """Forked from a server that preloaded them: a worker's first unit finds steadystep's units and matplotlib
    imported (they are not imported by the unit itself: sys.modules.__contains__ imports nothing)."""
    with study.make_executor("local") as pool:
        for name in ("steadystep.report.tasks", "matplotlib"):
            assert pool.submit(_imported, name).result(), name
    assert study.capacity(study.SerialExecutor()) == study.usable_cores()
