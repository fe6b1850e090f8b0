"""Source text a test puts at the top of a fresh process's script: a numba event listener
that counts every compilation of impactqp's kernels in ``Count.n`` (a kernel loaded from the
disk cache or run as Python text raises no compile event)."""

COUNTER = """
import numba.core.event as ev

class Count(ev.Listener):
    n = 0
    def on_start(self, event):
        d = (event.data or {}).get("dispatcher")
        if getattr(getattr(d, "py_func", None), "__module__", "").startswith("impactqp."):
            Count.n += 1
    def on_end(self, event):
        pass

ev.register("numba:compile", Count())
"""
