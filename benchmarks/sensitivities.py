"""The cost of derivatives through time: a Moreau–Jean run with its sensitivities beside the
same run without (target: at most 3×, issue 26), and the event-driven flow's likewise.

    python -m benchmarks.sensitivities [--steps 2000] [--repeats 50]

The bouncing ball (q₀ = 1, e = 0.9, g = 9.81, T = 1, h = T/steps), Newton's law, θ = 1/2;
the sensitivities with respect to q₀, v₀ and e (three tangent columns at every step). The
timer covers ``iq.simulate`` whole (set-up, the compiled loop, the derivative and, with
sensitivities, the tangents at every step); the two runs alternate, after one untimed warm-up
each, and the report gives the median and the fastest of each and their ratios.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import impactqp as iq

WRT = ("q0", "v0", "e")


def timings(scheme: str, steps: int, repeats: int) -> dict[str, float]:
    """Median and fastest seconds of the run without and with sensitivities, interleaved."""
    ball, law = iq.simulation.bouncing_ball(q0=1.0), iq.Newton(0.9)
    h = 1.0 / steps if scheme == "moreau-jean" else 0.01
    runs: dict[str, list[float]] = {"plain": [], "sensitivities": []}
    options = {"plain": {}, "sensitivities": {"sensitivities": WRT}}
    for label in runs:  # warm-up: compile and load the kernels
        iq.simulate(ball, law, 1.0, scheme=scheme, h=h, **options[label])
    for _ in range(repeats):
        for label, times in runs.items():
            start = time.perf_counter()
            iq.simulate(ball, law, 1.0, scheme=scheme, h=h, **options[label])
            times.append(time.perf_counter() - start)
    out = {}
    for label, times in runs.items():
        out[f"{label} median s"] = statistics.median(times)
        out[f"{label} fastest s"] = min(times)
    out["ratio (medians)"] = out["sensitivities median s"] / out["plain median s"]
    out["ratio (fastest)"] = out["sensitivities fastest s"] / out["plain fastest s"]
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.sensitivities",
                                     description=__doc__)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--repeats", type=int, default=50)
    args = parser.parse_args(argv)
    result = {f"{scheme} ({args.steps} steps)" if scheme == "moreau-jean" else scheme:
              timings(scheme, args.steps, args.repeats)
              for scheme in ("moreau-jean", "event-driven")}
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
