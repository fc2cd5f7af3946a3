#!/usr/bin/env bash
# Validates the Kubernetes manifests in docker/k8s/ offline, with no cluster: YAML, Kubernetes'
# schemas (kubernetes-models: its validators and TypeScript's checker over its types) and
# limn's own contract with them (tests/k8s/validate.mjs says which). Then proves it can fail:
# the validator's self-test breaks the manifests in memory in each way it checks, and a copy of
# docker/k8s/ with a misspelt field on disk must be refused.
# The npm packages are pinned by tests/k8s/package-lock.json and installed once into
# build/tools/k8s-validate. Where `kubectl` exists, its offline `kubectl kustomize` must also
# build each kustomization.
set -euo pipefail
cd "$(dirname "$0")/.."
tools=build/tools/k8s-validate
if ! cmp -s tests/k8s/package-lock.json "$tools/package-lock.json" ||
   [ ! -f "$tools/node_modules/kubernetes-models/package.json" ]; then
  # CI runs this before scripts/setup.sh: a fresh machine may have no node yet.
  node_packages=()
  command -v node >/dev/null || node_packages+=(nodejs)
  command -v npm >/dev/null || node_packages+=(npm)
  if [ ${#node_packages[@]} -gt 0 ]; then
    if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get -o DPkg::Lock::Timeout=600 update -qq
    $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends \
      "${node_packages[@]}" >/dev/null
  fi
  rm -rf "$tools"
  mkdir -p "$tools"
  cp tests/k8s/package.json tests/k8s/package-lock.json "$tools/"
  # No skipping here, unlike the OpenAPI lint: without its packages nothing would be checked.
  if ! (cd "$tools" && timeout 300 npm ci --silent --no-audit --no-fund >/dev/null 2>&1); then
    rm -f "$tools/package-lock.json"
    echo "validate-k8s: npm ci of tests/k8s/package-lock.json failed" >&2
    exit 1
  fi
fi
modules="$tools/node_modules"

node tests/k8s/validate.mjs --modules "$modules" docker/k8s
node tests/k8s/validate.mjs --modules "$modules" --self-test docker/k8s

# The same from the files: a misspelt field in a copy must fail the command line itself.
broken=$(mktemp -d)
trap 'rm -rf "$broken"' EXIT
cp -r docker/k8s/. "$broken/"
sed -i 's/^  replicas: /  replica: /' "$broken/deployment.yaml"
if node tests/k8s/validate.mjs --modules "$modules" "$broken" >"$broken.out" 2>&1; then
  echo "validate-k8s: FAIL: a Deployment with 'replica:' passed" >&2
  cat "$broken.out" >&2
  rm -f "$broken.out"
  exit 1
fi
grep -q "'replica' does not exist" "$broken.out" ||
  { echo "validate-k8s: FAIL: the misspelt field was refused for another reason:" >&2; cat "$broken.out" >&2; rm -f "$broken.out"; exit 1; }
rm -f "$broken.out"
echo "validate-k8s: a copy with a misspelt field is refused"

if command -v kubectl >/dev/null; then
  for dir in docker/k8s docker/k8s/batch docker/k8s/batch/report; do
    kubectl kustomize "$dir" >/dev/null || { echo "validate-k8s: kubectl kustomize $dir failed" >&2; exit 1; }
  done
  echo "validate-k8s: kubectl kustomize builds each kustomization"
fi
