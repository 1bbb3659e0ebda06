#!/usr/bin/env bash
# Validates deploy/k8s/*.yaml offline: Kubernetes and prometheus-operator JSON schemas (bundled by
# the npm package kubernetes-models, pinned in validate/package-lock.json), and the cross-checks of
# validate/validate.mjs (Envoy's ring hash on x-galpha-handle, probes, drain vs grace period).
set -euo pipefail
cd "$(dirname "$0")/validate"
npm ci --no-audit --no-fund --loglevel=error >/dev/null
node validate.mjs
