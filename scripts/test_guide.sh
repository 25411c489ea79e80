#!/usr/bin/env bash
# Builds the user guide (docs/guide, an mdBook) into a temporary folder: a chapter that
# SUMMARY.md lists but that is missing, or Markdown mdBook cannot render, fails the build.
# The links and anchors are checked by the Rust tests (tests/tests/doc_links.rs) and every
# command's chapter by crates/cli/tests/guide.rs. mdBook comes from crates.io, pinned
# (MDBOOK_VERSION) and built without its default features (the `serve`/`watch` web server
# and the search index are not needed to check the book), so that a cached ~/.cargo/bin is
# reused. Runs alone as well; `mdbook build docs/guide` writes the book to docs/guide/book/.
set -euo pipefail
cd "$(dirname "$0")/.."

MDBOOK_VERSION=0.5.4
if [ "$(mdbook --version 2>/dev/null)" != "mdbook v$MDBOOK_VERSION" ]; then
    echo "scripts/test_guide.sh: installing mdbook $MDBOOK_VERSION" >&2
    start=$(date +%s)
    cargo install mdbook --version "$MDBOOK_VERSION" --locked --no-default-features
    echo "scripts/test_guide.sh: cargo install mdbook took $(($(date +%s) - start)) s" >&2
fi

out="$(mktemp -d "${TMPDIR:-/tmp}/nacre-guide.XXXXXX")"
trap 'rm -rf "$out"' EXIT
mdbook build docs/guide --dest-dir "$out"
test -f "$out/index.html"
echo "scripts/test_guide.sh: the guide builds ($(find "$out" -name '*.html' | wc -l) pages)" >&2
