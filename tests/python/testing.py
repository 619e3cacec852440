# SPDX-License-Identifier: GPL-3.0-or-later
"""Runs a test file's test_* functions in order (plain asserts); exit status 1 on a failure."""
import os
import sys
import traceback

SOURCE_DIR = os.environ.get("SONOMAP_SOURCE_DIR",
                            os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
HERE = os.path.dirname(os.path.abspath(__file__))


def scene_file(name):
    """A scenario of tests/python."""
    return os.path.join(HERE, name)


def run(namespace):
    failed = 0
    for name, test in namespace.items():
        if not (name.startswith("test_") and callable(test)):
            continue
        try:
            test()
            print("ok  ", name)
        except Exception:  # a failed assert or an unexpected error
            failed += 1
            print("FAIL", name)
            traceback.print_exc()
    sys.exit(1 if failed else 0)
