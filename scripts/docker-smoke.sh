#!/usr/bin/env bash
# Prove the Dockerfile builds and serves, without a Docker daemon (Debian bookworm host, root):
#   1. debootstrap a minimal bookworm rootfs with Python 3.11 and import it as the base image
#      localhost/python:3.11-slim (skipped when that image already exists);
#   2. buildah bud --isolation chroot --build-arg BASE=localhost/python:3.11-slim -t jik .
#   3. inside a working container (buildah run --isolation chroot), as the image's user: run
#      `jik reproduce table1` and `jik errata`, start `jik serve`, fetch /health, /robots, /solve,
#      /docs and /errata, wait for the dashboard's first result over HTTP, and stop the server
#      with SIGTERM (what `docker stop` sends), checking that it exits cleanly.
# Usage: scripts/docker-smoke.sh [IMAGE]   (default IMAGE=localhost/jik:smoke)
#   JIK_SMOKE_REBUILD_BASE=1 rebuilds the base image; JIK_SMOKE_BASE_ONLY=1 stops after it.
# Not run in CI (slow); CI only lints the Dockerfile (tests/app/test_docker.py).
set -euo pipefail
cd "$(dirname "$0")/.."
IMAGE=${1:-localhost/jik:smoke}
BASE=localhost/python:3.11-slim
WORK=${JIK_SMOKE_DIR:-/var/tmp/jik-docker-smoke}
# Inside an unprivileged container overlayfs is rarely available; vfs always works.
export STORAGE_DRIVER=${STORAGE_DRIVER:-vfs}
export DEBIAN_FRONTEND=noninteractive
step() { printf '\n== %s (%s)\n' "$*" "$(date -u +%H:%M:%S)"; }

step "tools"
if ! command -v debootstrap >/dev/null || ! command -v buildah >/dev/null \
    || ! command -v podman >/dev/null; then
  apt-get update -qq
  apt-get install -y -qq debootstrap podman buildah >/dev/null
fi
buildah --version
podman --version

step "base image $BASE"
if [ "${JIK_SMOKE_REBUILD_BASE:-0}" = 1 ]; then podman rmi -f "$BASE" >/dev/null 2>&1 || true; fi
if podman image exists "$BASE"; then
  echo "reusing existing $BASE"
else
  # The mirror apt already uses (deb822 URIs: or one-line deb sources; comments ignored).
  MIRROR=$( { sed -n 's/^URIs:[[:space:]]*//p' /etc/apt/sources.list.d/*.sources 2>/dev/null;
             sed -n 's/^deb[[:space:]]\+\(\[[^]]*\][[:space:]]\+\)\?//p' /etc/apt/sources.list \
               2>/dev/null | cut -d' ' -f1; } | tr ' ' '\n' | grep -E '^https?://' \
             | grep -v security | head -n1 || true)
  MIRROR=${MIRROR:-http://deb.debian.org/debian}
  echo "mirror: $MIRROR"
  rm -rf "$WORK/rootfs"
  mkdir -p "$WORK"
  mkdir -p "$WORK/debs"
  debootstrap --variant=minbase --cache-dir="$WORK/debs" --include=python3,python3-venv,python3-pip,ca-certificates \
    bookworm "$WORK/rootfs" "$MIRROR" >"$WORK/debootstrap.log" 2>&1 \
    || { tail -n 30 "$WORK/debootstrap.log"; exit 1; }
  # This machine reaches PyPI through a TLS-intercepting proxy: the stand-in base trusts the
  # host's extra CAs, as the host does (the real python:3.11-slim needs nothing of the kind).
  if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
    cp /usr/local/share/ca-certificates/*.crt "$WORK/rootfs/usr/local/share/ca-certificates/"
    chroot "$WORK/rootfs" update-ca-certificates >/dev/null
  fi
  chroot "$WORK/rootfs" apt-get clean
  rm -rf "$WORK/rootfs/var/lib/apt/lists/"*
  CA=/etc/ssl/certs/ca-certificates.crt
  tar -C "$WORK/rootfs" -c . | podman import \
    --change 'CMD ["python3"]' --change 'ENV LANG=C.UTF-8' \
    --change "ENV PIP_CERT=$CA" --change "ENV SSL_CERT_FILE=$CA" \
    --change "ENV REQUESTS_CA_BUNDLE=$CA" - "$BASE"
  rm -rf "$WORK/rootfs"
fi
podman run --rm --network host "$BASE" python3 --version 2>/dev/null \
  || buildah run --isolation chroot "$(buildah from "$BASE")" -- python3 --version

if [ "${JIK_SMOKE_BASE_ONLY:-0}" = 1 ]; then exit 0; fi

step "hadolint"
if command -v hadolint >/dev/null; then hadolint Dockerfile && echo "hadolint: clean"; fi

step "build $IMAGE from $BASE"
buildah bud --isolation chroot --build-arg BASE="$BASE" -t "$IMAGE" .
buildah inspect --type image --format \
  'user={{.OCIv1.Config.User}} ports={{.OCIv1.Config.ExposedPorts}} cmd={{.OCIv1.Config.Cmd}}' \
  "$IMAGE"

step "reproduce table1, serve, and query the dashboard inside the container"
CTR=$(buildah from "$IMAGE")
trap 'buildah rm "$CTR" >/dev/null 2>&1 || true' EXIT
PORT=${JIK_SMOKE_PORT:-18000}
# Chroot isolation shares the host's network namespace, so a port other than 8000 avoids
# clashes with servers already running on the host. The image's user (10001) runs the server.
buildah run --isolation chroot --user 10001:10001 "$CTR" -- sh -c "
  id
  jik reproduce table1 || exit 1
  jik errata >/tmp/errata.md || exit 1
  head -n 1 /tmp/errata.md
  jik serve --host 127.0.0.1 --port $PORT >/tmp/serve.log 2>&1 &
  pid=\$!
  python - <<PY
import json, sys, time, urllib.request
for _ in range(120):
    try:
        with urllib.request.urlopen('http://127.0.0.1:$PORT/health', timeout=2) as r:
            print('GET /health ->', r.status, r.read().decode())
        with urllib.request.urlopen('http://127.0.0.1:$PORT/robots', timeout=10) as r:
            print('GET /robots ->', r.status, [x['name'] for x in json.load(r)['robots']])
        req = urllib.request.Request(
            'http://127.0.0.1:$PORT/solve',
            data=json.dumps({'robot': {'name': 'manipulator2'}, 'algorithm': 'pseudoinverse',
                             'x0': [0, 0, 1.5707963267948966], 'target': [1, 1]}).encode(),
            headers={'content-type': 'application/json'})
        with urllib.request.urlopen(req, timeout=30) as r:
            body = json.load(r)
            print('POST /solve ->', r.status, 'x =', [round(v, 4) for v in body['x']],
                  'converged =', body['converged'])
        with urllib.request.urlopen('http://127.0.0.1:$PORT/docs', timeout=10) as r:
            page = r.read().decode()
            print('GET /docs ->', r.status, 'cdn' not in page.lower() and 'assets served locally')
        with urllib.request.urlopen('http://127.0.0.1:$PORT/errata', timeout=10) as r:
            print('GET /errata ->', r.status, '<h1>Paper errata</h1>' in r.read().decode())
        req = urllib.request.Request(
            'http://127.0.0.1:$PORT/api/sessions', data=json.dumps({'state': {}}).encode(),
            headers={'content-type': 'application/json'})
        with urllib.request.urlopen(req, timeout=30) as r:
            session = json.load(r)['id']
            print('POST /api/sessions ->', r.status, 'a dashboard session')
        for _ in range(240):
            with urllib.request.urlopen('http://127.0.0.1:$PORT/api/sessions/' + session,
                                        timeout=10) as r:
                snapshot = json.load(r)
            if snapshot.get('summary'):
                print('dashboard: first result', json.dumps(snapshot['summary'])[:300])
                sys.exit(0)
            time.sleep(0.5)
        print('dashboard computed no result')
        sys.exit(1)
    except OSError:
        time.sleep(0.5)
print('server did not answer; log:')
print(open('/tmp/serve.log').read())
sys.exit(1)
PY
  rc=\$?
  kill -TERM \$pid
  wait \$pid
  stopped=\$?
  echo \"jik serve exited \$stopped after SIGTERM\"
  if grep -qE 'resource_tracker|Traceback' /tmp/serve.log; then cat /tmp/serve.log; exit 1; fi
  [ \$stopped -eq 0 ] || { cat /tmp/serve.log; exit 1; }
  exit \$rc
"
step "smoke test passed"
