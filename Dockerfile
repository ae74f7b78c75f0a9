# Serving image: the runtime install only (no torch), run as a non-root user.
FROM python:3.11-slim
ENV PYTHONDONTWRITEBYTECODE=1 PYTHONUNBUFFERED=1
WORKDIR /app
COPY pyproject.toml README.md ./
COPY golfflight ./golfflight
COPY service ./service
COPY shots ./shots
RUN pip install --no-cache-dir . && useradd --create-home --uid 10001 golfflight
USER golfflight
ENTRYPOINT ["golfflight"]
CMD ["fly", "--club", "Driver"]
