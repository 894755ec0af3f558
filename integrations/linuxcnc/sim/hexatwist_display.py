#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""LinuxCNC user interface for the tests (and the sample configuration's demo): no window.

LinuxCNC starts it as `[DISPLAY] DISPLAY` with `-ini FILE`. It reads a plan (JSON) from the file
named by $HEXATWIST_LINUXCNC_PLAN, drives the machine through LinuxCNC's Python interface (estop
reset, machine on, home, MDI moves, G-code programs) and writes what LinuxCNC reports after each
step to $HEXATWIST_LINUXCNC_RESULTS. When it exits, LinuxCNC shuts down.

A plan is {"steps": [step, ...], "pins": [HAL pin names read after each step]}; a step is one of
  {"home": true}                       estop reset, machine on, home all joints
  {"mdi": "G0 X1 Y2 ..."}               one MDI command, run to completion
  {"setp": {"pin": value, ...}}         sets HAL input pins (e.g. a leg's temperature), then lets
                                       a few servo cycles pass
  {"program": "/abs/file.ngc", "pauses": N}   a G-code program, held N times on its way (feed
                                       hold until the machine stands still) for a snapshot
  {"program": "/abs/file.ngc", "trace": S}    a G-code program run through, its commanded joints
                                       recorded every S seconds ("trace": [[t, j1..j6], ...], t
                                       from the start of the run)
Without $HEXATWIST_LINUXCNC_PLAN it runs a short demo and prints what it sees.
"""
import json
import os
import sys
import time

import hal
import linuxcnc

STEP_TIMEOUT = 60.0  # [s] for one move or program

# Reading HAL pins from Python needs a (passive) component of its own.
component = hal.component("hexatwist-driver")
component.ready()
stat = linuxcnc.stat()
command = linuxcnc.command()
errors = linuxcnc.error_channel()


def drain_errors():
    messages = []
    while True:
        e = errors.poll()
        if not e:
            return messages
        messages.append(e[1].strip())


def wait_until(condition, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        stat.poll()
        if condition():
            return True
        time.sleep(0.005)
    return False


def snapshot(pins):
    stat.poll()
    values = {}
    for name in pins:
        try:
            values[name] = hal.get_value(name)
        except Exception as e:  # a pin that does not exist is reported, not fatal here
            values[name] = "error: %s" % e
    return {
        "position": list(stat.position[:6]),  # commanded world pose
        "actual_position": list(stat.actual_position[:6]),  # world pose from the forward kinematics
        "joint_position": list(stat.joint_position[:6]),  # commanded joints
        "joint_actual_position": list(stat.joint_actual_position[:6]),
        "task_state": stat.task_state,
        "pins": values,
    }


def settled():
    return max(abs(a - c) for a, c in zip(stat.joint_actual_position[:6], stat.joint_position[:6])) <= 1e-9


def idle():
    return stat.interp_state == linuxcnc.INTERP_IDLE and stat.queue == 0 and stat.inpos


def home():
    command.state(linuxcnc.STATE_ESTOP_RESET)
    ok = wait_until(lambda: stat.task_state == linuxcnc.STATE_ESTOP_RESET, 10)
    command.state(linuxcnc.STATE_ON)
    ok = ok and wait_until(lambda: stat.task_state == linuxcnc.STATE_ON, 10)
    command.mode(linuxcnc.MODE_MANUAL)
    command.wait_complete()
    command.home(-1)
    ok = ok and wait_until(lambda: all(stat.homed[:6]), 20)
    ok = ok and wait_until(idle, 10)
    return ok


def mdi(text):
    command.mode(linuxcnc.MODE_MDI)
    command.wait_complete()
    command.mdi(text)
    command.wait_complete(STEP_TIMEOUT)
    return wait_until(idle, STEP_TIMEOUT)


def program(path, pauses, pins, trace_every=0.0, trace=None):
    """Runs a G-code program; `pauses` times, every 0.15 s, it holds the feed, waits until the
    machine stands still on the path, takes a snapshot and resumes. With `trace_every` > 0 the
    commanded joints are appended to `trace` as [t, j1..j6] that often, t from AUTO_RUN."""
    samples = []
    command.mode(linuxcnc.MODE_AUTO)
    command.wait_complete()
    command.program_open(path)
    command.wait_complete()
    command.auto(linuxcnc.AUTO_RUN, 0)
    t_run = time.monotonic()
    end = time.monotonic() + STEP_TIMEOUT
    started = wait_until(lambda: stat.interp_state != linuxcnc.INTERP_IDLE, 5)
    last = time.monotonic()
    while started and time.monotonic() < end and not idle():
        if trace_every > 0.0:
            stat.poll()
            trace.append([time.monotonic() - t_run] + list(stat.joint_position[:6]))
            time.sleep(trace_every)
            continue
        if len(samples) < pauses and time.monotonic() - last > 0.15:
            command.auto(linuxcnc.AUTO_PAUSE)
            if wait_until(lambda: stat.paused and stat.current_vel == 0.0, 5):
                time.sleep(0.02)
                samples.append(snapshot(pins))
            command.auto(linuxcnc.AUTO_RESUME)
            wait_until(lambda: not stat.paused, 5)
            last = time.monotonic()
        time.sleep(0.005)
        stat.poll()
    done = started and wait_until(idle, max(0.0, end - time.monotonic()))
    return done, samples


def run(plan):
    pins = plan.get("pins", [])
    results = []
    drain_errors()
    for step in plan["steps"]:
        record = {"step": step}
        if step.get("home"):
            record["done"] = home()
        elif "mdi" in step:
            record["done"] = mdi(step["mdi"])
        elif "setp" in step:
            for name, value in step["setp"].items():
                hal.set_p(name, repr(float(value)))
            record["done"] = True
        elif "program" in step:
            record["trace"] = []
            record["done"], record["samples"] = program(step["program"], step.get("pauses", 0), pins,
                                                        step.get("trace", 0.0), record["trace"])
        # The feedback and the pins settle: the simulated joints reach their commands (a loaded
        # machine may take more than a few servo cycles), then a few cycles more for the pins.
        wait_until(settled, 2.0)
        time.sleep(0.05)
        record["errors"] = drain_errors()
        record.update(snapshot(pins))
        results.append(record)
        if stat.task_state != linuxcnc.STATE_ON and not step.get("expect_off"):
            record["machine_off"] = True
            break
    return results


def demo():
    print("hexatwist LinuxCNC demo: home, then a few moves; each line: commanded pose, joints, pose from FK")
    steps = [{"home": True}, {"mdi": "G0 C20"}, {"mdi": "G0 Z1611 A5 B-5 C-20"}, {"mdi": "G0 X0 Y0 Z1511 A0 B0 C0"}]
    pins = ["hexatwistkins.leg.%d.twist" % i for i in range(1, 7)] + ["hexatwistkins.fk-iterations"]
    def tidy(v):  # rounding-level values as 0, so that the table shows 0.000000, not -0.000000
        return 0.0 if abs(v) < 5e-7 else v
    for r in run({"steps": steps, "pins": pins}):
        print("%-28s done=%s %s" % (json.dumps(r["step"]), r["done"], "; ".join(r["errors"])))
        print("   pose   " + " ".join("%11.6f" % tidy(v) for v in r["position"]))
        print("   joints " + " ".join("%11.6f" % tidy(v) for v in r["joint_position"]))
        print("   FK     " + " ".join("%11.6f" % tidy(v) for v in r["actual_position"]))
        print("   twist [deg] " + " ".join("%8.3f" % tidy(r["pins"][p]) for p in pins[:6]))


def main():
    plan_file = os.environ.get("HEXATWIST_LINUXCNC_PLAN")
    if not plan_file:
        demo()
        return 0
    with open(plan_file) as f:
        plan = json.load(f)
    results = run(plan)
    out = os.environ["HEXATWIST_LINUXCNC_RESULTS"]
    with open(out + ".tmp", "w") as f:
        json.dump({"results": results}, f)
    os.replace(out + ".tmp", out)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Exception as e:
        print("driver: %s: %s" % (type(e).__name__, e), file=sys.stderr)
        sys.exit(1)
