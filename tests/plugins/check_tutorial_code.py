#!/usr/bin/python3
"""docs/tutorials/05-your-own-integrator.md shows the complete example: its first ```cpp block must equal
examples/velocity-verlet/velocity_verlet.cpp and its first ```cmake block examples/velocity-verlet/CMakeLists.txt.
usage: check_tutorial_code.py SOURCE_DIR"""
import os
import re
import sys

src = sys.argv[1]
with open(os.path.join(src, "docs/tutorials/05-your-own-integrator.md"), encoding="utf-8") as f:
    doc = f.read()
for lang, path in (("cpp", "examples/velocity-verlet/velocity_verlet.cpp"), ("cmake", "examples/velocity-verlet/CMakeLists.txt")):
    m = re.search(r"```" + lang + r"\n(.*?)```", doc, re.S)
    with open(os.path.join(src, path), encoding="utf-8") as f:
        code = f.read()
    if not m or m.group(1) != code:
        print(f"FAIL: the tutorial's ```{lang} block is not {path} (copy the file into the page)")
        sys.exit(1)
print("tutorial code is the example's")
