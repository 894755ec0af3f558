# SPDX-License-Identifier: BSD-3-Clause
"""Starts a real LinuxCNC headless, runs a plan through sim/hexatwist_display.py, and always stops it.

Only one LinuxCNC runs on a machine (a lock file and fixed shared-memory keys): the tests that use
this module run one after the other (ctest's RESOURCE_LOCK linuxcnc), and a stale instance left by
a crash is cleaned up before and after each run.
"""
import filecmp
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DRIVER = os.path.join(os.path.dirname(HERE), "sim", "hexatwist_display.py")
LOCK_FILE = "/tmp/linuxcnc.lock"
# The programs a LinuxCNC session starts (exact process names).
PROGRAMS = ["linuxcncsvr", "milltask", "io", "iov2", "rtapi_app", "halcmd", "halui", "hexatwist_display.py"]
# rtapi_app refuses plain root: it runs as this fallback user (nobody).
FALLBACK_UID = "65534"


def _pids_of(names):
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/cmdline" % entry, "rb") as f:
                argv = f.read().split(b"\0")
            with open("/proc/%s/comm" % entry) as f:
                comm = f.read().strip()
        except OSError:
            continue
        words = [os.path.basename(a.decode(errors="replace")) for a in argv[:2] if a]
        if comm in names or any(w in names for w in words) or (words and words[0] == "bash" and
                                                               len(argv) > 1 and argv[1].endswith(b"/linuxcnc")):
            pids.append(int(entry))
    return pids


def _remove_shared_memory():
    # LinuxCNC's segments: HAL ("HAL2"), RTAPI ("HHL4"/uuid) and NML (keys 1001.. in linuxcnc.nml).
    out = subprocess.run(["ipcs", "-m"], capture_output=True, text=True).stdout
    for line in out.splitlines():
        fields = line.split()
        if len(fields) >= 6 and fields[0].startswith("0x") and fields[1].isdigit():
            key = int(fields[0], 16)
            if key in (0x48414C32, 0x48484C34) or 1000 <= key <= 1100 or key == 0:
                subprocess.run(["ipcrm", "-m", fields[1]], capture_output=True)


def clean_stale():
    """Stops every LinuxCNC process and removes its lock file and shared memory."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        pids = [p for p in _pids_of(PROGRAMS) if p != os.getpid()]
        for pid in pids:
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass
        if pids:
            time.sleep(0.3)
    if os.path.exists(LOCK_FILE):
        os.remove(LOCK_FILE)
    _remove_shared_memory()


def install_module(module_so):
    """Copies the built module where rtapi_app loads modules from (it loads from nowhere else)."""
    target_dir = os.environ.get("HEXATWIST_LINUXCNC_MODULES_DIR", "/usr/lib/linuxcnc/modules")
    target = os.path.join(target_dir, "hexatwistkins.so")
    if not (os.path.exists(target) and filecmp.cmp(module_so, target, shallow=False)):
        shutil.copyfile(module_so, target + ".tmp")
        os.replace(target + ".tmp", target)
    return target


def faster(ini, linear=2000.0, angular=120.0):
    """The INI with the axes' and trajectory's speeds raised, so that tests run quickly."""
    def sub(pattern, value):
        nonlocal ini
        ini = re.sub(r"(?m)^(%s) = .*$" % pattern, r"\1 = %s" % value, ini)
    sub("(?:DEFAULT|MAX)_LINEAR_VELOCITY", linear)
    sub("(?:DEFAULT|MAX)_LINEAR_ACCELERATION", 10 * linear)
    sub("(?:DEFAULT|MAX)_ANGULAR_VELOCITY", angular)
    sub("(?:DEFAULT|MAX)_ANGULAR_ACCELERATION", 10 * angular)
    sections = re.split(r"(?m)^(?=\[)", ini)
    for i, s in enumerate(sections):
        m = re.match(r"\[AXIS_([XYZABC])\]", s)
        if m:
            v = angular if m.group(1) in "ABC" else linear
            s = re.sub(r"(?m)^MAX_VELOCITY = .*$", "MAX_VELOCITY = %s" % v, s)
            s = re.sub(r"(?m)^MAX_ACCELERATION = .*$", "MAX_ACCELERATION = %s" % (10 * v), s)
        elif s.startswith("[JOINT_"):
            s = re.sub(r"(?m)^MAX_VELOCITY = .*$", "MAX_VELOCITY = %s" % (10 * linear), s)
            s = re.sub(r"(?m)^MAX_ACCELERATION = .*$", "MAX_ACCELERATION = %s" % (100 * linear), s)
        sections[i] = s
    return "".join(sections)


class LinuxcncRun:
    """What one LinuxCNC session reported: the driver's results and LinuxCNC's own output."""

    def __init__(self, results, log, returncode):
        self.results = results
        self.log = log
        self.returncode = returncode


def run(ini_text, plan, timeout=120.0, extra_hal=None, keep_dir=None):
    """Runs LinuxCNC with `ini_text` (its DISPLAY replaced by the test driver) and `plan`; returns a
    LinuxcncRun. Bounded by `timeout` seconds; LinuxCNC is stopped and cleaned up in every case."""
    work = tempfile.mkdtemp(prefix="hexatwist-linuxcnc-")
    os.chmod(work, 0o755)  # rtapi_app runs as the fallback user
    fifo_dir = os.path.join(work, "fifo")
    os.mkdir(fifo_dir)
    os.chmod(fifo_dir, 0o1777)
    ini_text = re.sub(r"(?m)^DISPLAY = .*$", "DISPLAY = %s" % DRIVER, ini_text)
    if extra_hal:
        with open(os.path.join(work, "extra.hal"), "w") as f:
            f.write(extra_hal)
        ini_text = re.sub(r"(?m)^(HALFILE = LIB:basic_sim.tcl.*)$", r"\1\nHALFILE = extra.hal", ini_text)
    ini = os.path.join(work, "machine.ini")
    with open(ini, "w") as f:
        f.write(ini_text)
    open(os.path.join(work, "hexatwist.tbl"), "w").close()
    plan_file = os.path.join(work, "plan.json")
    with open(plan_file, "w") as f:
        json.dump(plan, f)
    results_file = os.path.join(work, "results.json")
    env = dict(os.environ, RTAPI_UID=FALLBACK_UID, RTAPI_FIFO_PATH=os.path.join(fifo_dir, "rtapi_fifo"),
               HEXATWIST_LINUXCNC_PLAN=plan_file, HEXATWIST_LINUXCNC_RESULTS=results_file)
    log_file = os.path.join(work, "linuxcnc.log")
    clean_stale()
    returncode = None
    try:
        with open(log_file, "w") as log:
            proc = subprocess.Popen(["linuxcnc", "-r", ini], cwd=work, env=env, stdout=log, stderr=subprocess.STDOUT,
                                    stdin=subprocess.DEVNULL, start_new_session=True)
            try:
                returncode = proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                returncode = "timeout after %.0f s" % timeout
    finally:
        clean_stale()
    with open(log_file) as f:
        log_text = f.read()
    results = None
    if os.path.exists(results_file):
        with open(results_file) as f:
            results = json.load(f)["results"]
    if keep_dir:
        shutil.rmtree(keep_dir, ignore_errors=True)
        shutil.copytree(work, keep_dir, ignore=shutil.ignore_patterns("fifo"))
    shutil.rmtree(work, ignore_errors=True)
    return LinuxcncRun(results, log_text, returncode)
