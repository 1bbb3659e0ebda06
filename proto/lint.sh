#!/usr/bin/env bash
# Lints the API with buf (STANDARD rules but the service-name suffix: see buf.yaml). buf comes from
# the npm registry, pinned in lint/package-lock.json.
set -euo pipefail
cd "$(dirname "$0")"
# npm install, not npm ci: the lock lists other platforms' optional binaries of buf.
(cd lint && npm install --no-audit --no-fund --loglevel=error >/dev/null)
lint/node_modules/.bin/buf lint
echo "buf lint: clean"
