# Serving image: the runtime install only (no torch), the default model inside, run as a non-root user.
# No Docker engine runs on the project's machines: CI runs these install steps in a clean virtual environment
# instead (.ci/serving-install).
FROM python:3.11-slim
ENV PYTHONDONTWRITEBYTECODE=1 PYTHONUNBUFFERED=1
WORKDIR /app
COPY pyproject.toml README.md ./
# every package of the distribution: the command line registers them all; only the training commands import torch,
# and only when they run
COPY golfflight ./golfflight
COPY flight ./flight
COPY service ./service
COPY shots ./shots
COPY weights_schema ./weights_schema
COPY model_export ./model_export
COPY evaluation ./evaluation
COPY discovery ./discovery
COPY sweep ./sweep
COPY contract ./contract
COPY models/default ./models/default
# `pip install .` puts the bundle in /usr/local/share/golfflight/models/default (pyproject data-files)
RUN pip install --no-cache-dir . && rm -rf /app/* && useradd --create-home --uid 10001 golfflight
USER golfflight
WORKDIR /home/golfflight
# 8000: HTTP. 921: GSPro Open Connect over TCP, GSPro's own port, listened on only when the command asks:
#   docker run -p 8000:8000 -p 921:921 -e GOLFFLIGHT_API_KEY=... IMAGE \
#     serve --host 0.0.0.0 --port 8000 --connect-port 921 --connect-host 0.0.0.0
# (Open Connect has no key; a non-root user may bind 921 in a container since Docker 20.10, moby/moby#41030.)
# A --bay file must be in a folder that uid 10001 may write: each change is written beside it and renamed over it.
EXPOSE 8000
EXPOSE 921
HEALTHCHECK --interval=15s --timeout=3s --start-period=10s --retries=3 \
    CMD ["python", "-c", "import urllib.request, sys; sys.exit(urllib.request.urlopen('http://127.0.0.1:8000/healthz', timeout=2).status != 200)"]
ENTRYPOINT ["golfflight"]
CMD ["serve", "--host", "0.0.0.0", "--port", "8000"]
