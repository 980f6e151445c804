#!/usr/bin/env python3
"""The wall time of every built-in sampler's default prediction, against a time target.

Run from the repository root after `cargo build --release` (only Python 3 is needed):

    python3 benches/compare/default_predictions.py --n 65536 --target 2 \\
        --integrands 'gaussian:sigma=0.2,c=0.2;0.7' 'edge:theta=30,offset=0.4' disk

For each sampler that draws N points in the dimension asked (`specvar samplers --json`), each
integrand is predicted twice with `specvar predict -s S -n N -f F`: the first run fills the
pattern cache (a costly sampler draws its patterns there), the second is timed, as a user's
warm call. A row reads the warm wall time, whether it is within the target ("refused" where
the command exits with an error), and the route or the refusal; a run past `--timeout` is
stopped and reported as such.
"""
import argparse
import json
import subprocess
import time

BINARY = "target/release/specvar"


def samplers(dimension):
    listed = json.loads(subprocess.run([BINARY, "samplers", "--json"], check=True,
                                       capture_output=True, text=True).stdout)
    return [s["name"] for s in listed
            if s["min_dimension"] <= dimension <= s["max_dimension"]]


def run(args, timeout):
    """Wall seconds and the first line that says what happened, or None past the timeout."""
    start = time.perf_counter()
    try:
        done = subprocess.run([BINARY, *args], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, f"stopped after {timeout} s"
    seconds = time.perf_counter() - start
    lines = (done.stdout + done.stderr).splitlines()
    said = next((l for l in lines if l.startswith(("route", "error"))), "")
    return seconds, said


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, required=True)
    parser.add_argument("-d", "--dimension", type=int, default=2)
    parser.add_argument("--integrands", nargs="+", default=["gaussian", "disk"])
    parser.add_argument("--samplers", nargs="*", help="default: every sampler of the dimension")
    parser.add_argument("--target", type=float, default=2.0, help="seconds, warm")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds per run")
    args = parser.parse_args()
    names = args.samplers or samplers(args.dimension)
    print(f"| sampler | integrand | warm wall s | within {args.target:g} s | route or refusal |")
    print("|---|---|---|---|---|")
    for name in names:
        for f in args.integrands:
            call = ["predict", "-d", str(args.dimension), "-s", name, "-n", str(args.n), "-f", f]
            cold, said = run(call, args.timeout)
            warm, said = run(call, args.timeout) if cold is not None else (None, said)
            shown = "—" if warm is None else f"{warm:.2f}"
            if said.startswith("error"):
                ok = "refused"
            else:
                ok = "no" if warm is None or warm > args.target else "yes"
            print(f"| {name} | `{f}` | {shown} | {ok} | {said[:110]} |", flush=True)


if __name__ == "__main__":
    main()
