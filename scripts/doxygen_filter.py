#!/usr/bin/env python3
"""Doxygen INPUT_FILTER (scripts/Doxyfile): turns the plain // comments of a header into Doxygen comments.

A run of // lines directly above a declaration becomes its /// documentation; a trailing // comment after
a declaration on the same line becomes ///<. Characters Doxygen would read as commands or HTML (\\ @ < > &
# % $) are escaped, so the comments appear as written. Lines are kept one for one (line numbers stay right).
"""
import re
import sys

ESC = str.maketrans({"\\": "\\\\", "@": "\\@", "<": "\\<", ">": "\\>", "&": "\\&", "#": "\\#", "%": "\\%",
                     "$": "\\$"})


def main():
    text = open(sys.argv[1], encoding="utf-8", errors="replace").read()
    out = []
    in_block = False
    for line in text.split("\n"):
        s = line.lstrip()
        if "/*" in s and "*/" not in s:
            in_block = True
        if in_block:
            out.append(line)
            if "*/" in s:
                in_block = False
            continue
        m = re.match(r"^(\s*)//(?!/)\s?(.*)$", line)
        if m:
            body = m.group(2)
            if body.startswith(("---", "===", "clang-format", "NOLINT")) or not body.strip():
                out.append(m.group(1) + "//")
            else:
                out.append(m.group(1) + "/// " + body.translate(ESC))
            continue
        m = re.match(r"^(.*?[;{,])(\s*)//(?!/)\s?(.*)$", line)
        if m and '"' not in m.group(1):
            out.append(m.group(1) + m.group(2) + "///< " + m.group(3).translate(ESC))
            continue
        out.append(line)
    sys.stdout.write("\n".join(out))


main()
