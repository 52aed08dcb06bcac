#!/usr/bin/env python3
"""The Python module's cost over the C++ it calls (issue 17's targets, docs/benchmarks.md).

Two measurements, both on one real volume and one frame setting:

1. Frame overhead. The same 512^2 frame is rendered N times by `lacuna render --repeat N` (the
   CLI: one process, one lacuna::Session, the median of frames 2..N of the renderer's own timer)
   and by lacuna.Session.render() in this process (wall time of the whole Python call around the
   same Session::render, and that frame's own renderer timer). The two run interleaved, round
   after round, so that the shared machine's load falls on both alike; the medians over every
   round are reported, with process CPU time per frame. The overhead of the Python call is
     (a) per frame, in the same process: wall of render() - the renderer's seconds of that frame
         (kwargs to FrameSpec, validate, the result's arrays and dict, the GIL hand-over);
     (b) across processes: Python's render() wall median / the CLI's frame median - 1, which
         also carries any difference of the two builds of the library (the module links a
         position-independent copy, python/CMakeLists.txt).
   The frames are checked byte for byte against the CLI's PNG first.

2. TF edit. On bitfield and minmax: `session.transfer_function = tf` (the Python setter: the
   LUT through lacuna::Session) plus the next frame's structure update (stats
   'tf_sync_seconds'), the bitfield paper's "TF change to ready to render". The next frame is
   compared byte for byte with a fresh session's frame of that TF. The CLI's
   `--tf-animate A B` TF-change column (its median-free mean over the frames) is printed beside.

Run from the source tree after a build:
    python3 bench/python_overhead.py --build build [--rounds 7] [--frames 21] [--threads 1,2]
(/usr/bin/python3 on Debian: the interpreter CMake built the module for.) Timings never gate
anything; the script exits non-zero only if a frame is not the CLI's.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--build", default="build", help="build directory (lacuna, python/)")
    p.add_argument("--cli", default=None, help="the lacuna CLI (default: BUILD/lacuna)")
    p.add_argument("--volume", default="/usr/share/mricron/templates/ch2.nii.gz")
    p.add_argument("--tf", default="mr-skin")
    p.add_argument("--tf2", default="mr-brain", help="the TF the edit switches to")
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--accel", default="auto", help="structure of the overhead frames")
    p.add_argument("--shading", default="none")
    p.add_argument("--rounds", type=int, default=7, help="interleaved CLI/Python rounds")
    p.add_argument("--frames", type=int, default=21, help="frames per round (first one: warm-up)")
    p.add_argument("--threads", default="1,2", help="comma-separated thread counts")
    p.add_argument("--tf-edits", type=int, default=21, help="TF edits timed per structure")
    return p.parse_args()


def cli_frames(cli, args, threads, out):
    """`lacuna render --repeat N`: (median frame ms, its CPU ms)."""
    cmd = [cli, "render", args.volume, "--tf", args.tf, "--size", str(args.size),
           "--accel", args.accel, "--threads", str(threads), "--repeat", str(args.frames),
           "--shading", args.shading, "-o", out]
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    m = re.search(r"render time ([\d.]+) ms, .* CPU ([\d.]+) ms", r.stdout)
    if not m:
        sys.exit("unexpected CLI output:\n" + r.stdout)
    return float(m.group(1)), float(m.group(2))


def python_frames(session, args):
    """N frames through Session.render(): per frame (wall s, CPU s, renderer s), frame 1 dropped."""
    out = []
    kw = dict(size=args.size, structure=args.accel, shading=args.shading)
    for i in range(args.frames):
        c0, t0 = time.process_time(), time.perf_counter()
        f = session.render(**kw)
        t1, c1 = time.perf_counter(), time.process_time()
        if i:
            out.append((t1 - t0, c1 - c0, f.stats["seconds"]))
    return out, f


def main():
    args = parse_args()
    build = os.path.abspath(args.build)
    sys.path.insert(0, os.path.join(build, "python"))
    import numpy as np
    import lacuna

    cli = args.cli or os.path.join(build, "lacuna")
    tmp = tempfile.mkdtemp(prefix="lacuna-pybench-")
    png = os.path.join(tmp, "cli.png")
    vol = lacuna.load(args.volume)
    print("python_overhead: %s, tf %s, %dx%d, accel %s, shading %s, %d rounds x %d frames"
          % (args.volume, args.tf, args.size, args.size, args.accel, args.shading, args.rounds,
             args.frames))
    print("date %s, host %s, load %s" % (time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                                         os.uname().nodename,
                                         " ".join("%.1f" % x for x in os.getloadavg())))
    for threads in [int(t) for t in args.threads.split(",")]:
        session = lacuna.Session(vol, args.tf, threads=threads)
        cli_ms, cli_cpu, py_wall, py_cpu, py_render, py_over = [], [], [], [], [], []
        for r in range(args.rounds):
            ms, cpu = cli_frames(cli, args, threads, png)
            cli_ms.append(ms)
            cli_cpu.append(cpu)
            frames, last = python_frames(session, args)
            if r == 0 and not np.array_equal(last.image, lacuna.read_png(png)):
                sys.exit("!!! the Python frame is not the CLI's (threads %d)" % threads)
            py_wall += [w * 1e3 for w, _, _ in frames]
            py_cpu += [c * 1e3 for _, c, _ in frames]
            py_render += [s * 1e3 for _, _, s in frames]
            py_over += [(w - s) * 1e3 for w, _, s in frames]
        med = statistics.median
        cli_med = med(cli_ms)  # the median of the rounds' medians
        wall_med = med(py_wall)
        print("threads %d: frames byte-identical to the CLI's" % threads)
        print("  CLI   lacuna render --repeat %d: frame median %.2f ms (rounds %s), CPU %.2f ms"
              % (args.frames, cli_med, " ".join("%.1f" % x for x in cli_ms), med(cli_cpu)))
        print("  Python Session.render():        wall median %.2f ms, CPU %.2f ms; its renderer"
              " timer %.2f ms" % (wall_med, med(py_cpu), med(py_render)))
        print("  (a) call overhead in-process: median %.3f ms = %.2f%% of the frame (max %.3f ms)"
              % (med(py_over), 100 * med(py_over) / med(py_render), max(py_over)))
        print("  (b) Python wall / CLI frame: %.2f%% (%+.2f ms)"
              % (100 * (wall_med / cli_med - 1), wall_med - cli_med))

    # ---- TF edits on bitfield and minmax.
    tf_a, tf_b = lacuna.TransferFunction(args.tf), lacuna.TransferFunction(args.tf2)
    print("TF edit %s <-> %s through Python, %d edits per structure, %dx%d frames, 1 thread"
          % (args.tf, args.tf2, args.tf_edits, args.size, args.size))
    for accel in ("bitfield", "minmax"):
        s = lacuna.Session(vol, tf_a, threads=1)
        kw = dict(size=args.size, structure=accel, refine=False)
        s.render(**kw)  # built for tf_a
        setter, sync, total = [], [], []
        for i in range(args.tf_edits):
            tf = tf_b if i % 2 == 0 else tf_a
            t0 = time.perf_counter()
            s.transfer_function = tf
            t1 = time.perf_counter()
            f = s.render(**kw)
            setter.append((t1 - t0) * 1e3)
            sync.append(f.stats["tf_sync_seconds"] * 1e3)
            total.append(setter[-1] + sync[-1])
            if i < 2:
                ref = lacuna.Session(vol, tf, threads=1).render(**kw).image
                if not np.array_equal(f.image, ref):
                    sys.exit("!!! %s: the frame after the TF edit is not a fresh session's" % accel)
        r = subprocess.run([cli, "render", args.volume, "--tf-animate", args.tf, args.tf2,
                            "--frames", "5", "--accel", accel, "--size", "64", "--threads", "1",
                            "-o", os.path.join(tmp, "anim.png")],
                           capture_output=True, text=True, check=True)
        row = [ln for ln in r.stdout.splitlines() if ln.startswith(accel + " ")]
        med = statistics.median
        print("  %-8s setter median %.4f ms + structure update median %.4f ms = %.4f ms "
              "(max %.4f); next frame == fresh session's frame" % (
                  accel, med(setter), med(sync), med(total), max(total)))
        if row:
            print("           CLI --tf-animate (LUT + update, mean, max): %s ms"
                  % " ".join(row[0].split()[2:4]))


if __name__ == "__main__":
    main()
