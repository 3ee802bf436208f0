# jik: REST API, dashboard and its 3D scenes, all on port 8000.
#   docker build -t jik . && docker run -p 8000:8000 jik
# BASE can point at any Debian-like image with Python 3.11 or newer and venv
# (scripts/docker-smoke.sh builds one with debootstrap).
ARG BASE=python:3.11-slim

# Stage 1: the wheel, built from the source as `pip wheel .` builds it for any user.
FROM ${BASE} AS wheel
ENV PIP_NO_CACHE_DIR=1 PIP_DISABLE_PIP_VERSION_CHECK=1
WORKDIR /src
COPY . .
RUN python3 -m venv /opt/build \
    && /opt/build/bin/python -m pip wheel --no-cache-dir --no-deps -w /wheels . \
    && printf 'jik-lab[app] @ file://%s\n' /wheels/jik_lab-*.whl > /wheels/requirements.txt

# Stage 2: that wheel and the web extra in a venv owned by root; the server runs unprivileged.
FROM ${BASE}
ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    VIRTUAL_ENV=/opt/jik \
    PATH=/opt/jik/bin:$PATH
COPY --from=wheel /wheels /wheels
RUN python3 -m venv /opt/jik \
    && groupadd --gid 10001 jik \
    && useradd --create-home --uid 10001 --gid 10001 --shell /usr/sbin/nologin jik \
    && python -m pip install --no-cache-dir --requirement /wheels/requirements.txt \
    && rm -rf /wheels \
    && python -c "import jik.app.api.factory, jik.engine.reproductions.table1"

USER 10001:10001
WORKDIR /home/jik
EXPOSE 8000
CMD ["jik", "serve", "--host", "0.0.0.0", "--port", "8000"]
