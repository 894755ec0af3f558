# SPDX-License-Identifier: BSD-3-Clause
"""The numbered examples come in pairs (Ruckig's habit): examples/NN_topic.cpp and
examples/python/NN_topic.py call the same functions of the library on the same data and print the same
lines (the Python one may add its figure's path, or the truth it compares with, after them); the
real-time loops print the same commands and counts, their timings being their own."""
import glob
import os
import re
import subprocess
import sys

import pytest

SOURCE = os.environ.get("HEXATWIST_SOURCE_DIR", "")
BUILD = os.environ.get("HEXATWIST_BUILD_DIR", "")
pytestmark = pytest.mark.skipif(not (SOURCE and BUILD), reason="run through ctest")


def numbered(pattern):
    return {os.path.basename(p).split("_", 1)[0]: p for p in glob.glob(os.path.join(SOURCE, pattern))}


def test_every_number_has_one_example_in_each_language_on_one_topic():
    cpp, py = numbered("examples/[0-9][0-9]_*.cpp"), numbered("examples/python/[0-9][0-9]_*.py")
    assert set(cpp) == set(py) and len(cpp) >= 8
    for number in cpp:
        topic = os.path.splitext(os.path.basename(cpp[number]))[0]
        assert os.path.splitext(os.path.basename(py[number]))[0] == topic


def run_pair(number, tmp_path):
    cpp, py = numbered("examples/[0-9][0-9]_*.cpp")[number], numbered("examples/python/[0-9][0-9]_*.py")[number]
    name = os.path.splitext(os.path.basename(cpp))[0]
    binary = os.path.join(BUILD, "examples", f"example_{name}")
    if not os.path.exists(binary):
        pytest.skip(f"{binary} not built")
    with open(py) as f:
        py_args = [str(tmp_path)] if "[out_dir]" in f.read() else []
    # Both run as a user would from a folder of their own: the data files are found without an argument.
    c = subprocess.run([binary], capture_output=True, text=True, timeout=240, cwd=tmp_path)
    p = subprocess.run([sys.executable, py, *py_args], capture_output=True, text=True, timeout=240,
                       env=dict(os.environ, MPLBACKEND="Agg"), cwd=tmp_path)
    assert c.returncode == 0 and p.returncode == 0, c.stderr + p.stderr
    return c.stdout.splitlines(), p.stdout.splitlines()


@pytest.mark.parametrize("number", ["01", "02", "04", "05", "06", "07", "08"])
def test_the_pair_prints_the_same_lines(number, tmp_path):
    cpp, py = run_pair(number, tmp_path)
    assert len(cpp) >= 2 and py[:len(cpp)] == cpp, "\n".join(["C++:", *cpp, "Python:", *py])


@pytest.mark.parametrize("name", ["06_identify", "07_motor_sizing"])
def test_a_missing_data_folder_is_one_line_naming_the_file(name, tmp_path):
    binary = os.path.join(BUILD, "examples", f"example_{name}")
    if not os.path.exists(binary):
        pytest.skip(f"{binary} not built")
    r = subprocess.run([binary, str(tmp_path / "nowhere")], capture_output=True, text=True, timeout=60)
    lines = r.stderr.splitlines()
    assert r.returncode == 1 and len(lines) == 1, r.stderr
    assert lines[0].startswith(f"example_{name}: {tmp_path / 'nowhere'}/") and "No such file" in lines[0], lines[0]


def test_the_realtime_loops_send_the_same_commands(tmp_path):
    cpp, py = run_pair("03", tmp_path)
    tail = re.compile(r"rejected cues: 1 \(held: 1\); rate-limited ticks: \d+; leg 1 ends at [-\d.]+ m$")
    same = [tail.search(lines[-1]) for lines in (cpp, py)]
    assert all(same) and same[0].group(0) == same[1].group(0), (cpp[-1], py[-1])
