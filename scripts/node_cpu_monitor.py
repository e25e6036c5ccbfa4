#!/usr/bin/env python3
"""CPU per scan of the laser odometry's worker thread while a paused bag.launch player plays a bag.

Started by scripts/node_cpu.sh once the launch is up. Finds the process of `--node` (the nodelet manager or
the standalone node) through the master, subscribes /tf (which a robot always has; the node publishes one
odom -> base transform per scan processed) and, on each of the node's transforms, reads every thread's CPU
time from /proc/PID/task/*/schedstat. The difference between two consecutive transforms is one whole cycle
of the worker: waiting, taking the queued inputs, conversion, matching, publishing and bookkeeping. The
worker is the thread named "laser_odometry" (the node names it; with several laser odometry nodelets in one
manager, the first such thread found, so run one as scripts/node_cpu.sh does); its wake-ups are the times it
was scheduled in. A build that does not name it is refused: the thread of the most CPU is not always the
worker (replaying with --clock, roscpp's poll thread takes 100 /clock messages a second and outspends a
light worker).
Prints one line of `key value` pairs.
"""
import argparse
import math
import os
import signal
import subprocess
import sys
import threading
import time
import xmlrpc.client

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from std_srvs.srv import SetBool
from tf2_msgs.msg import TFMessage


def node_pid(name):
    master = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])
    code, _, uri = master.lookupNode("/node_cpu_monitor", name)
    if code != 1:
        return None
    code, _, pid = xmlrpc.client.ServerProxy(uri).getPid("/node_cpu_monitor")
    return pid if code == 1 else None


def loaded_library(pid, name, wait=30.0):
    """Path of the shared library `name` in the process (the nodelet loads it once the manager is up)."""
    deadline = time.time() + wait
    while True:
        with open("/proc/%d/maps" % pid) as f:
            for line in f:
                if line.rstrip().endswith("/" + name):
                    return line.split()[-1]
        if time.time() > deadline:
            return ""
        time.sleep(0.2)


WORKER_NAME = "laser_odometry"


def worker_tid(pid):
    """The thread of `pid` named WORKER_NAME, or None."""
    task_dir = "/proc/%d/task" % pid
    for tid in os.listdir(task_dir):
        try:
            with open("%s/%s/comm" % (task_dir, tid)) as f:
                if f.read().strip() == WORKER_NAME:
                    return int(tid)
        except OSError:
            pass
    return None


def thread_cpu_ns(pid):
    """{tid: (nanoseconds on CPU, times scheduled in)} of every thread of `pid`."""
    times = {}
    task_dir = "/proc/%d/task" % pid
    for tid in os.listdir(task_dir):
        try:
            with open("%s/%s/schedstat" % (task_dir, tid)) as f:
                fields = f.read().split()
                times[int(tid)] = (int(fields[0]), int(fields[2]))
        except (OSError, ValueError, IndexError):
            pass  # a thread that ended meanwhile
    return times


def median(sorted_values):
    half = len(sorted_values) // 2
    if len(sorted_values) % 2:
        return sorted_values[half]
    return 0.5 * (sorted_values[half - 1] + sorted_values[half])


def percentile(sorted_values, fraction):
    """Nearest rank, as evaluate's (hglasm::spreadOf)."""
    rank = int(math.ceil(fraction * len(sorted_values)))
    return sorted_values[min(len(sorted_values) - 1, max(rank - 1, 0))]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--node", default="/laser_odometry_manager")
    parser.add_argument("--scans", type=int, required=True, help="scans in the bag")
    parser.add_argument("--odom-frame", default="odom")
    parser.add_argument("--base-frame", default="base_link")
    parser.add_argument("--player", default="/player")
    parser.add_argument("--timeout", type=float, default=600.0, help="wall seconds for the whole replay")
    parser.add_argument("--library", default="", help="fail unless libhglasm_ros.so is loaded from under it")
    parser.add_argument("--perf", default="", help="also record the process with perf into this file")
    parser.add_argument("--idle", type=float, default=10.0, help="stop after this long without a transform")
    args = parser.parse_args(rospy.myargv()[1:])

    rospy.init_node("node_cpu_monitor", disable_signals=True)
    deadline = time.time() + 60.0
    pid = None
    while pid is None and time.time() < deadline:
        pid = node_pid(args.node)
        if pid is None:
            time.sleep(0.2)
    if pid is None:
        sys.exit("node_cpu_monitor: %s not found" % args.node)

    library = loaded_library(pid, "libhglasm_ros.so")
    if not library.startswith(args.library):
        sys.exit("node_cpu_monitor: %s loaded %s, not one under %s" % (args.node, library, args.library))

    samples = []  # per transform: {tid: ns}
    lock = threading.Lock()
    last_arrival = [time.time()]

    def on_tf(msg):
        for t in msg.transforms:
            if t.header.frame_id == args.odom_frame and t.child_frame_id == args.base_frame:
                times = thread_cpu_ns(pid)
                with lock:
                    samples.append(times)
                    last_arrival[0] = time.time()
                return

    perf = None
    if args.perf:
        perf = subprocess.Popen(["perf", "record", "-q", "-F", "2000", "-g", "-p", str(pid), "-o", args.perf],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    self_mean = ["nan"]  # the node's own figure: CPU of conversion, matching and publishing, per scan

    def on_diagnostics(msg):
        for status in msg.status:
            for value in status.values:
                if value.key == "CPU per scan, mean (ms)":
                    with lock:
                        self_mean[0] = value.value

    rospy.Subscriber("/tf", TFMessage, on_tf, queue_size=10000, tcp_nodelay=True)
    rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=10)
    rospy.wait_for_service(args.player + "/pause_playback", timeout=60.0)
    time.sleep(1.0)  # the /tf connection is up
    rospy.ServiceProxy(args.player + "/pause_playback", SetBool)(False)
    start = time.time()
    last_arrival[0] = start
    while time.time() - start < args.timeout:
        with lock:
            done = len(samples) >= args.scans or time.time() - last_arrival[0] > args.idle
        if done:
            break
        time.sleep(0.2)
    with lock:
        samples = list(samples)
    if perf:
        perf.send_signal(signal.SIGINT)
        perf.wait()
    time.sleep(2.5)  # the next /diagnostics (every diagnostics/period, 1 s) covers the last scan
    if len(samples) < 3:
        sys.exit("node_cpu_monitor: only %d transforms from the node" % len(samples))

    first, last = samples[0], samples[-1]
    totals = {tid: last[tid][0] - first.get(tid, (0, 0))[0] for tid in last}
    worker = worker_tid(pid)
    if worker is None or worker not in first or worker not in last:
        sys.exit("node_cpu_monitor: no thread named %s in %s (a build that does not name its worker)"
                 % (WORKER_NAME, args.node))
    per_scan = sorted((b[worker][0] - a.get(worker, b[worker])[0]) * 1e-6 for a, b in zip(samples, samples[1:]))
    cycles = len(samples) - 1
    wakeups = (last[worker][1] - first[worker][1]) / cycles
    process_ms = sum(totals.values()) * 1e-6 / cycles
    print("library %s" % library)
    with lock:
        node_mean = self_mean[0]
    print("transforms %d cycles %d worker_mean %.4f worker_median %.4f worker_p99 %.4f process_mean %.4f "
          "self_mean %s worker_wakeups %.2f" % (len(samples), cycles, sum(per_scan) / cycles, median(per_scan),
                                                percentile(per_scan, 0.99), process_ms, node_mean, wakeups))


if __name__ == "__main__":
    main()
