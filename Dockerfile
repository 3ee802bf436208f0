# jik: REST API (port 8000) and viser 3D scene (port 8080).
#   docker build -t jik . && docker run -p 8000:8000 -p 8080:8080 jik
# BASE can point at any Debian-like image with Python 3.11 and venv (scripts/docker-smoke.sh
# builds one with debootstrap).
ARG BASE=python:3.11-slim
FROM ${BASE}

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    VIRTUAL_ENV=/opt/jik \
    PATH=/opt/jik/bin:$PATH

# The package goes into a venv owned by root; the server runs as an unprivileged user.
RUN python3 -m venv /opt/jik \
    && groupadd --gid 10001 jik \
    && useradd --create-home --uid 10001 --gid 10001 --shell /usr/sbin/nologin jik

WORKDIR /src
COPY . .
RUN python -m pip install --no-cache-dir . \
    && python -c "import app.main, engine.registry"

USER 10001:10001
WORKDIR /home/jik
EXPOSE 8000 8080
CMD ["jik", "serve", "--host", "0.0.0.0", "--port", "8000", "--scene-port", "8080"]
