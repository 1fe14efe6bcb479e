"""What the end-to-end app tests share: their arguments and work folder, and
the check that prints what held or stops the test with what did not."""
import shutil
import os
import sys


def setup():
    """BIN_DIR SOURCE_DIR WORK_DIR from the command line, WORK_DIR emptied."""
    bin_dir, src, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    return bin_dir, src, work


def check(cond, what):
    if not cond:
        sys.exit("FAIL: " + what)
    print("ok:", what)
