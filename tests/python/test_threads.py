"""The GIL is released while a scenario runs: another Python thread runs meanwhile, runs on several threads give
the results of one thread, and one Scenario object runs on two threads at once."""

import threading
import time

import redres
from conftest import source


def test_python_threads_run_while_a_scenario_runs():
    # 40 s at tau = 0.5 ms: 80,000 steps of the paper's eq. 15, about 0.2 s in the release build: long enough to watch.
    s = redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={"step": 0.0005})
    span = {}

    def work():
        span["start"] = time.perf_counter()
        s.run()
        span["end"] = time.perf_counter()

    worker = threading.Thread(target=work)
    worker.start()
    ticks = []
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.0005)
    worker.join()
    inside = [t for t in ticks if span["start"] + 0.02 < t < span["end"] - 0.02]
    assert span["end"] - span["start"] > 0.06, "the run was too short to tell"
    assert len(inside) >= 5, f"the main thread ran {len(inside)} times during a {span['end'] - span['start']:.3f} s run"


def test_parallel_runs_give_the_results_of_sequential_runs():
    files = [source(f"configs/paper_r_{n}.toml") for n in ("tvcmm", "constant_p", "mvn", "fast")]
    one = redres.compare(files, jobs=1)
    two = redres.compare(files, jobs=2)
    for a, b in zip(one.results, two.results):
        assert a.final_theta.tolist() == b.final_theta.tolist()
        assert (a.values == b.values).all()


def test_one_scenario_runs_on_two_threads_at_once():
    # The scenario is only read by its runs: the two runs overlap (each reports progress while the other does) and
    # each gives what a run alone gives.
    s = redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={"step": 0.0005})
    alone = s.run()
    seen = [[], []]
    results = [None, None]

    def work(i):
        results[i] = s.run(progress=lambda fraction, t: seen[i].append(time.perf_counter()))

    threads = [threading.Thread(target=work, args=(i,)) for i in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert seen[0] and seen[1]
    assert seen[1][0] < seen[0][-1] and seen[0][0] < seen[1][-1], "the second run waited for the first"
    for r in results:
        assert (r.values == alone.values).all()
        assert r.final_theta.tolist() == alone.final_theta.tolist()
