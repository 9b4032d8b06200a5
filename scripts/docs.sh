#!/usr/bin/env bash
# Builds the documentation site into build/site/ from docs/ (MkDocs, mkdocs.yml) with the C++ API reference
# of the installed headers in build/site/api/ (Doxygen, scripts/Doxyfile; any Doxygen warning is an error).
# The generated reference pages (docs/reference/cli.md, integrators.md) are first refreshed from build/bin
# when it exists (scripts/make_reference.py). Needs: bash scripts/install-deps.sh --with-docs.
#   bash scripts/docs.sh           # build the site
#   bash scripts/docs.sh --check   # build it, then open it in headless Chromium: links and images (scripts/check_site.py)
set -euo pipefail
cd "$(dirname "$0")/.."
for tool in mkdocs doxygen; do
  command -v "$tool" >/dev/null || { echo "docs.sh: $tool not found: bash scripts/install-deps.sh --with-docs" >&2; exit 77; }
done
if [ -x build/bin/shelldyn ]; then
  python3 scripts/make_reference.py --bin build/bin
else
  echo "docs.sh: build/bin/shelldyn not built; docs/reference/cli.md and integrators.md left as they are"
fi
mkdocs build --quiet --clean -f mkdocs.yml 2> build/mkdocs.log || { cat build/mkdocs.log >&2; exit 1; }
grep -v 'is included in the .nav. configuration, which is not found\|^$' build/mkdocs.log >&2 || true
mkdir -p build
rm -rf build/doxygen
doxygen scripts/Doxyfile
if [ -s build/doxygen-warnings.log ]; then
  echo "docs.sh: Doxygen warnings (build/doxygen-warnings.log):" >&2
  head -20 build/doxygen-warnings.log >&2
  exit 1
fi
rm -rf build/site/api
cp -r build/doxygen/html build/site/api
pages=$(find build/site -name '*.html' -not -path 'build/site/api/*' | wc -l)
api=$(find build/site/api -name '*.html' | wc -l)
echo "docs.sh: site in build/site/index.html ($pages pages), API reference in build/site/api/index.html ($api pages), 0 Doxygen warnings"
if [ "${1:-}" = "--check" ]; then
  python3 scripts/check_site.py build/site
fi
