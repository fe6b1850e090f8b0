"""Sweeps on several local processes and on a Dask cluster give the same results as one
process."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.verification.parallel import DASK_MIN_IMPACTS, run_chunks, split

CRADLE = iq.newtons_cradle(3)
A, B = np.linspace(0.0, 1.0, 5), np.linspace(-0.5, 1.0, 4)


def test_split_covers_everything_in_order() -> None:
    for n, jobs in ((0, 1), (1, 1), (17, 1), (100, 2), (5, 8)):
        spans = split(n, jobs)
        assert [k for r in spans for k in r] == list(range(n))
    spans = split(1000, 2, client=object(), impacts_per_item=50)
    assert all(len(r) * 50 >= DASK_MIN_IMPACTS for r in spans[:-1])


def test_local_processes_keep_order_and_results() -> None:
    def square(r: range) -> list[int]:  # a closure: forked workers inherit it
        return [k * k for k in r]

    chunks = split(37, 3)
    assert run_chunks(square, chunks, n_jobs=3) == run_chunks(square, chunks, n_jobs=1)


def test_fremond_map_does_not_depend_on_workers() -> None:
    one = iq.verification.fremond_admissibility_map(CRADLE, A, B, samples=40, seed=3)
    two = iq.verification.fremond_admissibility_map(CRADLE, A, B, samples=40, seed=3, n_jobs=2)
    np.testing.assert_array_equal(one, two)
    assert one.any() and not one.all()  # the map has both verdicts: the test can fail


def test_bad_jobs_and_client() -> None:
    with pytest.raises(iq.InputError, match="n_jobs"):
        iq.verification.fremond_admissibility_map(CRADLE, A, B, n_jobs=0)
    with pytest.raises(iq.InputError, match="client"):
        iq.verification.fremond_admissibility_map(CRADLE, A, B, client="localhost")


def test_dask_local_cluster_gives_the_same_map() -> None:
    distributed = pytest.importorskip("distributed", reason="the optional dask extra")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        on_dask = iq.verification.fremond_admissibility_map(CRADLE, A, B, samples=40, seed=3,
                                               client=client)
    np.testing.assert_array_equal(on_dask,
                                  iq.verification.fremond_admissibility_map(CRADLE, A, B,
                                                                            samples=40, seed=3))


def test_verify_law_does_not_depend_on_workers() -> None:
    law = lambda q: iq.newton(q, [1.0, 0.5])  # noqa: E731 (a closure, inherited by forking)
    one = iq.verify_law(law, CRADLE, samples=120, seed=2, consistent_only=False)
    two = iq.verify_law(law, CRADLE, samples=120, seed=2, consistent_only=False, n_jobs=2)
    assert one.violations == two.violations and one.violations["non_expansive"] > 0
    for name, example in one.counterexamples.items():
        np.testing.assert_array_equal(example.u_plus, two.counterexamples[name].u_plus)


def test_verify_law_takes_law_objects() -> None:
    report = iq.verify_law(iq.Moreau(1.0), CRADLE, samples=60)
    assert report.ok and report.samples == 60
    assert not iq.verify_law(iq.Fremond([[1.0, 0.5], [0.5, 1.0]]), CRADLE, samples=30).ok
