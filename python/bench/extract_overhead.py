#!/usr/bin/env python3
"""The cost of extracting one frame through Python against C++, measured in the same run on
the same image (docs/python.md#speed).

  extract_overhead.py BENCHMARK IMAGE SENSOR [--rounds 5] [--repetitions 5]

BENCHMARK is bench/extract's extract_benchmark (its BM_FrontEnd_File: FeaturePipeline::process
on IMAGE with SENSOR, the frame object reused); the Python side times
omnivert.FeaturePipeline(SENSOR).process(image) with timeit (a new FrameFeatures per call, as
a Python user gets it). Rounds alternate the two, so that a change of the machine's load
falls on both; each side's figure is the median over every repetition of every round (the
time per frame of one repetition: its mean over many frames), in real time and in the
process's CPU time (every thread). Prints the medians in ms and their ratios.
"""
import argparse
import json
import os
import statistics
import subprocess
import time
import timeit

import omnivert


def cpp_times(benchmark, image, sensor, repetitions):
    env = dict(os.environ, OMNIVERT_BENCH_IMAGE=image, OMNIVERT_BENCH_SENSOR=sensor)
    out = subprocess.run([benchmark, "--benchmark_filter=^BM_FrontEnd_File/",
                          f"--benchmark_repetitions={repetitions}", "--benchmark_format=json",
                          "--benchmark_min_time=0.5"],
                         env=env, check=True, capture_output=True, text=True).stdout
    runs = json.loads(out)["benchmarks"]
    runs = [r for r in runs if r.get("run_type") == "iteration"]
    return [r["real_time"] for r in runs], [r["cpu_time"] for r in runs]


def python_times(pipe, image, repetitions):
    pipe.process(image)
    n = max(1, int(0.5 / min(timeit.repeat(lambda: pipe.process(image), number=1, repeat=3))))
    real = timeit.repeat(lambda: pipe.process(image), number=n, repeat=repetitions)
    cpu = timeit.repeat(lambda: pipe.process(image), number=n, repeat=repetitions,
                        timer=time.process_time)
    return [1000.0 * x / n for x in real], [1000.0 * x / n for x in cpu]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("benchmark")
    ap.add_argument("image")
    ap.add_argument("sensor")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--repetitions", type=int, default=5)
    a = ap.parse_args()
    image = omnivert.read_image(a.image)
    pipe = omnivert.FeaturePipeline(omnivert.load_camera_geometry(a.sensor))
    cpp, py, cpp_cpu, py_cpu = [], [], [], []
    for r in range(a.rounds):
        real, cpu = cpp_times(a.benchmark, a.image, a.sensor, a.repetitions)
        cpp += real
        cpp_cpu += cpu
        real, cpu = python_times(pipe, image, a.repetitions)
        py += real
        py_cpu += cpu
        print(f"round {r + 1}: C++ {statistics.median(cpp):.3f} ms, "
              f"Python {statistics.median(py):.3f} ms", flush=True)
    m = statistics.median
    print(f"{image.shape[1]}x{image.shape[0]}, {len(pipe.process(image))} lines; median per "
          f"frame over {len(cpp)} and {len(py)} repetitions: real time C++ {m(cpp):.3f} ms, "
          f"Python {m(py):.3f} ms, Python / C++ = {m(py) / m(cpp):.3f}; process CPU time C++ "
          f"{m(cpp_cpu):.3f} ms, Python {m(py_cpu):.3f} ms, Python / C++ = "
          f"{m(py_cpu) / m(cpp_cpu):.3f}; load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
