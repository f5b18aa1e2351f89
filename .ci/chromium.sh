#!/usr/bin/env bash
# Install Debian's chromium for the report's browser test (tests/test_report_browser.py).
# Usage: source .ci/chromium.sh   (idempotent and quiet; never fails CI: without chromium
# the browser test is skipped with its reason).
if command -v chromium >/dev/null 2>&1; then
    echo "chromium for the report's browser test: $(chromium --version 2>/dev/null | head -n 1)"
elif (apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
        apt-get install -y -qq chromium) >/dev/null 2>&1; then
    echo "chromium installed for the report's browser test: $(chromium --version 2>/dev/null | head -n 1)"
else
    echo "chromium could not be installed: the report's browser test will be skipped" >&2
fi
true
