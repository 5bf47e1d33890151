"""``iemd-compile``: compile the tracker's and the gyro's numba kernels into numba's cache beside the installed
package, so that the first start of the node or of ``iemd-replay`` compiles nothing.

Run at install time (``scripts/setup_venv.sh``, and ``setup.py install``/``develop`` as colcon runs them); it takes
10-30 s once per install.  Without it the first start compiles them and says so.
"""
from __future__ import annotations

import sys
import time

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    """Compile (or load) every kernel and print where the cache is and how long it took.

    Parameters
    ----------
    argv : list of str, optional
        No arguments are taken.

    Returns
    -------
    int
        0.
    """
    if argv is None:
        argv = sys.argv[1:]
    if argv:
        print("usage: iemd-compile (no arguments)", file=sys.stderr)
        return 2
    start = time.perf_counter()
    from iemd_ros.pipeline.pipeline import kernel_cache_dir, warm_up_kernels

    cached = warm_up_kernels()
    print(f"iemd-compile: numba kernels {'loaded from' if cached else 'compiled into'} the cache in "
          f"{kernel_cache_dir()} in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
