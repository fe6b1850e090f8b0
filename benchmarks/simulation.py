"""Simulation benchmark: impactqp's Moreau–Jean (``iq.simulate``) beside Siconos' MoreauJeanOSI.

    python -m benchmarks.simulation [--systems ball,cradle,column] [--sizes 3,10,100]
                                    [--steps 1000] [--repeats 5]

Three systems, built the same way in both codes (Newton's law in the Moreau–Jean step form,
θ = 1/2, contacts closed when the gap predicted half a step ahead is ≤ 0, Siconos' ``LCP``
one-step problem with its default Lemke solver):

``ball``
    Siconos' BouncingBallTS example as it ships: a ball of radius 0.1, m = 1, q₀ = 1, v₀ = 0,
    g = 9.81, e = 0.9, h = 0.005, T = 10 (2000 steps). Siconos' model has 3 DOF (height,
    horizontal position, angle; inertia 2/5·m·r²) and the relation y = q₀ (height of the
    lowest point); impactqp's ``iq.simulation.bouncing_ball()`` is its one moving DOF. Both
    record the height and velocity at every step (the example stores them too), and the agreement is
    the largest difference over the whole trajectory.
``cradle``
    Newton's cradle on pendulums, ``iq.simulation.cradle_system(N)``: linearized pendulums
    (restoring force −(mg/L)qᵢ, L = 1), gaps q_{i+1} − qᵢ, the left ball released from −0.1; e = 1,
    h = 10⁻³. In Siconos: one ``LagrangianLinearTIDS`` per ball with stiffness K = mg/L and
    one ``LagrangianLinearTIR`` H = (−1, 1) per neighbour pair.
``column``
    A column of beads falling on the ground, ``iq.simulation.bead_chain`` (m = 1, R = 0.1,
    1 mm apart, the lowest 1 mm above the ground), e = 0.9, h = 10⁻³.

impactqp's timer covers ``iq.simulate`` (its set-up included, the model built before);
Siconos' covers the ``computeOneStep``/``nextStep`` loop (the model and simulation objects
built before). Siconos runs in ``--siconos-python`` (Debian's ``/usr/bin/python3`` with
python3-siconos), where this file serves runs over a pipe (its top-level imports are the
standard library only), so the two codes run interleaved — impactqp, Siconos, impactqp, … —
after one untimed warm-up each. Without siconos the comparison is skipped, never an error.
"""

from __future__ import annotations

import argparse
import json
import queue
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

THETA = 0.5
GRAVITY = 9.81
#: per system: time step and Newton restitution
STEP = {"ball": 0.005, "cradle": 1e-3, "column": 1e-3}
RESTITUTION = {"ball": 0.9, "cradle": 1.0, "column": 0.9}
#: BouncingBallTS: ball radius (its inertia only), mass, initial height
BALL_RADIUS, BALL_MASS, BALL_Q0 = 0.1, 1.0, 1.0
#: cradle: pendulum length and the released ball's initial displacement
LENGTH, AMPLITUDE = 1.0, 0.1
#: column: bead radius and the initial gaps
RADIUS, GAP = 0.1, 1e-3
SICONOS_PYTHON = "/usr/bin/python3"
#: the prefix of the server's answer lines (anything else on its stdout is Siconos talking)
ANSWER = "@@ "


def column(n: int) -> list[float]:
    """The beads' initial heights (shared by both codes)."""
    return [RADIUS + GAP + i * (2 * RADIUS + GAP) for i in range(n)]


# --- impactqp --------------------------------------------------------------------------------
def impactqp_model(system: str, n: int) -> Any:
    """The ``iq.LinearSystem`` of ``system`` with ``n`` balls (the ball has one)."""
    import impactqp as iq

    if system == "ball":  # radius 0: the height of the lowest point, as in Siconos' example
        return iq.simulation.bouncing_ball(mass=BALL_MASS, q0=BALL_Q0, v0=0.0, gravity=GRAVITY)
    if system == "cradle":
        return iq.simulation.cradle_system(n, mass=1.0, length=LENGTH, gravity=GRAVITY,
                                amplitude=AMPLITUDE)
    return iq.simulation.bead_chain(n, radius=RADIUS, height=RADIUS + GAP, spacing=2 * RADIUS + GAP,
                         gravity=GRAVITY)


def impactqp_run(system: str, n: int, steps: int) -> tuple[float, dict[str, list[float]]]:
    """Seconds of ``iq.simulate`` over ``steps`` steps, and the state to compare: the ball's
    height and velocity at every step, else the final positions and velocities."""
    import impactqp as iq

    model, h = impactqp_model(system, n), STEP[system]
    every = 1 if system == "ball" else steps
    start = time.perf_counter()
    tr = iq.simulate(model, iq.Newton(RESTITUTION[system]), steps * h, h=h, theta=THETA,
                     keep_events=False, record_every=every)
    seconds = time.perf_counter() - start
    if system == "ball":
        return seconds, {"q": tr.q[:, 0].tolist(), "v": tr.v[:, 0].tolist()}
    return seconds, {"q": tr.q[-1].tolist(), "v": tr.v[-1].tolist()}


# --- Siconos (runs in the interpreter that imports siconos) ----------------------------------
def siconos_run(system: str, n: int, steps: int) -> tuple[float, dict[str, list[float]]]:
    """The same run with Siconos' kernel; same return value as :func:`impactqp_run`."""
    import siconos.kernel as sk

    h = STEP[system]
    nsds = sk.NonSmoothDynamicalSystem(0.0, steps * h)
    law = sk.NewtonImpactNSL(RESTITUTION[system])
    bodies = []
    if system == "ball":  # BouncingBallTS.py
        mass = [[BALL_MASS, 0.0, 0.0], [0.0, BALL_MASS, 0.0],
                [0.0, 0.0, 2.0 / 5.0 * BALL_MASS * BALL_RADIUS**2]]
        ball = sk.LagrangianLinearTIDS([BALL_Q0, 0.0, 0.0], [0.0, 0.0, 0.0], mass)
        ball.setFExtPtr([-BALL_MASS * GRAVITY, 0.0, 0.0])
        nsds.insertDynamicalSystem(ball)
        nsds.link(sk.Interaction(law, sk.LagrangianLinearTIR([[1.0, 0.0, 0.0]])), ball)
        bodies.append(ball)
    elif system == "cradle":
        k = GRAVITY / LENGTH  # m = 1
        for i in range(n):
            ds = sk.LagrangianLinearTIDS([-AMPLITUDE if i == 0 else 0.0], [0.0], [[1.0]],
                                         [[k]], [[0.0]])
            nsds.insertDynamicalSystem(ds)
            bodies.append(ds)
    else:
        for q in column(n):
            ds = sk.LagrangianLinearTIDS([q], [0.0], [[1.0]])
            ds.setFExtPtr([-GRAVITY])
            nsds.insertDynamicalSystem(ds)
            bodies.append(ds)
        ground = sk.Interaction(law, sk.LagrangianLinearTIR([[1.0]], [-RADIUS]))
        nsds.link(ground, bodies[0])
    if system != "ball":
        offset = [-2 * RADIUS] if system == "column" else [0.0]
        for a, b in zip(bodies, bodies[1:]):
            pair = sk.Interaction(law, sk.LagrangianLinearTIR([[-1.0, 1.0]], offset))
            nsds.link(pair, a, b)
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, h), sk.MoreauJeanOSI(THETA),
                          sk.LCP())
    q, v = [BALL_Q0], [0.0]
    start = time.perf_counter()
    if system == "ball":
        for _ in range(steps):
            sim.computeOneStep()
            q.append(float(ball.q()[0]))
            v.append(float(ball.velocity()[0]))
            sim.nextStep()
    else:
        for _ in range(steps):
            sim.computeOneStep()
            sim.nextStep()
    seconds = time.perf_counter() - start
    if system != "ball":
        q = [float(ds.q()[0]) for ds in bodies]
        v = [float(ds.velocity()[0]) for ds in bodies]
    return seconds, {"q": q, "v": v}


def serve() -> int:
    """Answer run requests, one JSON line ``{"system", "n", "steps"}`` per run, until EOF."""
    for line in sys.stdin:
        job = json.loads(line)
        try:
            seconds, state = siconos_run(job["system"], job["n"], job["steps"])
            answer = {"seconds": seconds, **state}
        except Exception as exc:  # reported to the caller, the server goes on
            answer = {"error": f"{type(exc).__name__}: {exc}"}
        sys.stdout.write(ANSWER + json.dumps(answer) + "\n")
        sys.stdout.flush()
    return 0


class SiconosServer:
    """A script serving Siconos runs in ``python`` over a pipe; one process for a whole
    comparison. By default this file (Moreau–Jean runs, :meth:`run`); ``script`` and
    ``flag`` name another server that answers JSON lines the same way (:meth:`request`),
    such as :mod:`benchmarks.siconos_worker`'s fc3d solvers."""

    def __init__(self, python: str, script: Path | None = None,
                 flag: str = "--siconos-serve") -> None:
        self.errors = tempfile.TemporaryFile("w+")  # a pipe left unread could fill and block
        where = script or Path(__file__).resolve()
        self.proc = subprocess.Popen([python, str(where), flag],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.errors, text=True)
        self._lines: queue.Queue[str | None] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        """Forward the server's output lines to :meth:`request` (None at its end)."""
        for line in self.proc.stdout:
            self._lines.put(line)
        self._lines.put(None)

    @property
    def alive(self) -> bool:
        """Is the server still running (it dies with a crash of Siconos)?"""
        return self.proc.poll() is None

    def request(self, job: dict[str, Any], timeout: float | None = None) -> dict[str, Any]:
        """Send one JSON request, return the answer.

        Raises
        ------
        RuntimeError
            The server reports an error, or has died (its last words are in the message).
        TimeoutError
            No answer within ``timeout`` seconds: the server is killed (start another).
        """
        try:
            self.proc.stdin.write(json.dumps(job) + "\n")
            self.proc.stdin.flush()
        except (BrokenPipeError, ValueError):
            pass  # it has died: its last words are read below
        else:
            while True:
                try:
                    line = self._lines.get(timeout=timeout)
                except queue.Empty:
                    self.proc.kill()
                    self.close()
                    raise TimeoutError(f"siconos gave no answer within {timeout:g} s "
                                       "(server stopped)") from None
                if line is None:
                    break
                if line.startswith(ANSWER):
                    answer = json.loads(line[len(ANSWER):])
                    if "error" in answer:
                        raise RuntimeError(f"siconos: {answer['error']}")
                    return answer
        self.proc.wait(timeout=60)  # its output ended: it is exiting
        self.errors.seek(0)
        message = self.errors.read().strip()[-300:]
        self.close()
        raise RuntimeError(f"siconos server died (exit {self.proc.returncode}): {message}")

    def run(self, system: str, n: int, steps: int) -> tuple[float, dict[str, list[float]]]:
        """Seconds and state of one Siconos run (raises RuntimeError when it fails)."""
        answer = self.request({"system": system, "n": n, "steps": steps})
        return answer.pop("seconds"), answer

    def close(self) -> None:
        """End the server (it exits at the end of its input)."""
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait(timeout=60)
        elif not self.proc.stdin.closed:
            try:
                self.proc.stdin.close()
            except BrokenPipeError:
                pass
        if not self.errors.closed:
            self.errors.close()

    def __enter__(self) -> SiconosServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def siconos_available(python: str) -> tuple[str | None, str]:
    """(interpreter that imports siconos.kernel, or None; the reason when None)."""
    try:
        import siconos.kernel  # noqa: F401
        return sys.executable, ""
    except ImportError:
        pass
    if not python:
        return None, "no Siconos interpreter given"
    try:
        check = subprocess.run([python, "-c", "import siconos.kernel"], capture_output=True,
                               text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return None, f"cannot run {python}: {exc}"
    if check.returncode != 0:
        return None, f"{python} cannot import siconos.kernel"
    return python, ""


def agreement(mine: dict[str, list[float]], theirs: dict[str, list[float]]) -> float:
    """Largest |Δq| or |Δv| between two states (or trajectories) of the same run."""
    if any(len(mine[k]) != len(theirs[k]) for k in ("q", "v")):
        return float("inf")
    return max(abs(a - b) for k in ("q", "v") for a, b in zip(mine[k], theirs[k]))


def compare(system: str, n: int, steps: int, repeats: int,
            server: SiconosServer | None) -> dict[str, Any]:
    """Warm both up, then run them interleaved ``repeats`` times.

    Returns
    -------
    dict
        ``impactqp`` and ``siconos`` (lists of seconds; the latter empty without a server),
        ``agreement`` (None without Siconos) and ``error`` (Siconos' failure, or "").
    """
    impactqp_run(system, n, steps)  # compiles, fills caches
    out: dict[str, Any] = {"impactqp": [], "siconos": [], "agreement": None, "error": ""}
    try:
        if server is not None:
            server.run(system, n, steps)
    except RuntimeError as exc:
        out["error"], server = str(exc), None
    for _ in range(repeats):
        seconds, mine = impactqp_run(system, n, steps)
        out["impactqp"].append(seconds)
        if server is not None:
            seconds, theirs = server.run(system, n, steps)
            out["siconos"].append(seconds)
            out["agreement"] = agreement(mine, theirs)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.simulation",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--systems", default="ball,cradle,column")
    parser.add_argument("--sizes", default="5,100",
                        help="balls of the cradle and the column (the ball has one)")
    parser.add_argument("--steps", type=int, default=1000,
                        help="steps of the cradle and the column (the ball runs 2000)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--siconos-python", default=SICONOS_PYTHON,
                        help="interpreter that imports siconos ('' skips the peer)")
    parser.add_argument("--siconos-serve", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.siconos_serve:
        return serve()
    python, why = siconos_available(args.siconos_python)
    if python is None:
        print(f"siconos: {why}; comparison skipped")
    print(f"Moreau–Jean θ = {THETA}, median of {args.repeats} interleaved runs")
    print(f"{'system':>7} {'N':>5} {'steps':>6} | {'impactqp':>9} | {'Siconos':>9} | "
          f"{'ratio':>6} | max |Δ|")
    server = SiconosServer(python) if python else None
    try:
        for system in args.systems.split(","):
            sizes = [1] if system == "ball" else [int(s) for s in args.sizes.split(",")]
            steps = 2000 if system == "ball" else args.steps
            for n in sizes:
                out = compare(system, n, steps, args.repeats, server)
                mine = statistics.median(out["impactqp"])
                theirs = statistics.median(out["siconos"]) if out["siconos"] else None
                peer = f"{theirs:9.4f}" if theirs else f"{'—':>9}"
                ratio = f"{mine / theirs:6.2f}" if theirs else f"{'—':>6}"
                diff = "" if out["agreement"] is None else f"{out['agreement']:.1e}"
                print(f"{system:>7} {n:>5} {steps:>6} | {mine:9.4f} | {peer} | {ratio} | "
                      f"{diff} {out['error']}")
    finally:
        if server is not None:
            server.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
