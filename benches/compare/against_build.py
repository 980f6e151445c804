#!/usr/bin/env python3
"""The specvar command line of this checkout against that of an earlier commit, interleaved.

Run from the repository root (only the Rust toolchain and Python 3 are needed):

    python3 benches/compare/against_build.py 57e8c15 --rounds 24 -- \\
        --no-cache spectrum -s jitter -n 4096 --kmax 320 -m 64 --radial

It builds both (the earlier commit in a temporary git worktree with its own target
directory), then runs the two binaries with the given arguments in alternating order, round
after round, and prints the wall time of each (least and median, in ms) and the median over
rounds of the ratio earlier / now: on a machine whose speed drifts, only times taken side by
side compare.
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import sys
import time


def build(checkout, target):
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=checkout, check=True,
                   env={**os.environ, "CARGO_TARGET_DIR": target})
    return os.path.join(target, "release", "specvar")


def wall_ms(binary, args):
    start = time.perf_counter()
    subprocess.run([binary, *args], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return (time.perf_counter() - start) * 1e3


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     epilog="then -- and the arguments of specvar")
    parser.add_argument("commit", help="the earlier commit")
    parser.add_argument("--rounds", type=int, default=16)
    ours = sys.argv[1:]
    split = ours.index("--") if "--" in ours else len(ours)
    opts = parser.parse_args(ours[:split])
    args = ours[split + 1:]
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    with tempfile.TemporaryDirectory() as tmp:
        tree = os.path.join(tmp, "tree")
        subprocess.run(["git", "worktree", "add", "--detach", "--quiet", tree, opts.commit],
                       cwd=root, check=True)
        try:
            binaries = {
                opts.commit: build(tree, os.path.join(tmp, "target")),
                "now": build(root, os.path.join(root, "target")),
            }
            times = {name: [] for name in binaries}
            with tempfile.TemporaryDirectory() as scratch:
                os.chdir(scratch)
                for r in range(opts.rounds):
                    order = list(binaries) if r % 2 == 0 else list(binaries)[::-1]
                    for name in order:
                        times[name].append(wall_ms(binaries[name], args))
        finally:
            os.chdir(root)
            subprocess.run(["git", "worktree", "remove", "--force", tree], cwd=root, check=True)
    ratios = [a / b for a, b in zip(times[opts.commit], times["now"])]
    print(f"specvar {' '.join(args)}: {opts.rounds} rounds, alternating")
    for name, values in times.items():
        print(f"  {name:>12}: least {min(values):7.1f} ms, median {statistics.median(values):7.1f} ms")
    print(f"  median of the ratios {opts.commit} / now: {statistics.median(ratios):.2f}")


if __name__ == "__main__":
    main()
