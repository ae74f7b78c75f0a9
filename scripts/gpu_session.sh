#!/usr/bin/env bash
# Issue 33's GPU measurements on a machine lent by the `device` tool, prepared here and run there in two commands
# (a third where time is left).
#
# A session is lent 15 minutes of device time in all, the machine's start (1-2 minutes) included, and a machine is
# started only with 4 minutes left; so each command runs in about 4.5 minutes, leaving time to start again and rerun
# one, and the measurements the issue's targets need come first.
#
# The lent machine's image has PyTorch (2.11, CUDA), onnxruntime, pyarrow, numpy and scipy but neither pydantic nor
# Ray, reaches no package index and has no shared data. So, here, first:
#     bash scripts/gpu_session.sh prepare
# downloads the wheels it lacks (pydantic and its four needs, for its Python 3.12; .whl/, 2.8 MB) and builds the
# train-real file (build/real_flights.csv and its trajectories, by model_export.real_data.build: the held-out sets
# are never read). Then, each as one `run` carrying [".whl", "build"] with timeout_s 300, results back in $OUT:
#     bash scripts/gpu_session.sh flight   # bench_gpu.py: shots/s at 16,384 to 4,194,304 shots eager, compiled and
#                                          # with none set aside; parity on 10,000 mixed shots; 10,000,000-launch
#                                          # sweeps to Parquet in one process, compiled, and in 4 (at most 250 s)
#     bash scripts/gpu_session.sh train    # bench_train.py: 16 seeds side by side on cuda, eager and compiled; then
#                                          # the same machine's 16 cores as 16 processes (at most 270 s)
# and, only with 6 minutes of device time left after those (a third command, on the warm machine):
#     bash scripts/gpu_session.sh more     # the CPU's share of a sweep, the ground phase on the CPU, smaller batches,
#                                          # sweeps in 2 processes, one seed on cuda (at most 270 s)
# Each step has its own time limit, and benchmarks/results.json (each script writes its rows as it measures them)
# is copied into $OUT after each, so a step cut short keeps what the others measured. Each command's results.json
# holds its own measurements: `more` writes bench_gpu's section anew, so merge its rows by hand.
# --ray-workers is left out: Ray's wheel alone is over the 64 MiB a call may carry.
set -uo pipefail
cd "$(dirname "$0")/.."

WHEELS=(pydantic==2.14.4 pydantic_core==2.50.5 annotated-types==0.8.0 typing-inspection==0.4.5 typing_extensions==4.16.0)
TRAIN_FILE=build/real_flights.csv

prepare() {
    grep -qx "/.whl/" .git/info/exclude 2>/dev/null || echo "/.whl/" >> .git/info/exclude
    python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
        --platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 \
        -d .whl "${WHEELS[@]}" || exit 1
    python3 -c "from golfflight.model_export.real_data import build; from golfflight.shots.paths import shared_data_dir; \
build(shared_data_dir(), '$TRAIN_FILE')" || exit 1
    du -sh .whl build
}

on_device() {
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl \
        || exit 1
    export PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1
    nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader
    python3 -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name())"
}

step() {  # step NAME SECONDS COMMAND...: run it under a time limit, its output in $OUT/NAME.log, its rows merged into
    # the copy's benchmarks/results.json (--results: the scripts write nowhere unless told), then copied out
    local name=$1 limit=$2
    shift 2
    echo "== $* (at most ${limit} s)"
    timeout "$limit" "$@" --results benchmarks/results.json 2>&1 | tee "$OUT/$name.log"
    cp benchmarks/results.json "$OUT/results.json"
}

case "${1:-}" in
    prepare) prepare ;;
    flight)
        on_device
        step flight 250 python3 benchmarks/bench_gpu.py --device cuda --engines compiled,none-set-aside \
            --batches 16384,1048576,4194304 --share-rows 0 --sweep-rows 10000000 --torch-workers 4 --sweep-timeout 60
        ;;
    train)
        on_device
        step train-cuda 180 python3 benchmarks/bench_train.py --device cuda --data "$TRAIN_FILE" --runs 16 --compile \
            --no-count-ops
        step train-cpu 80 python3 benchmarks/bench_train.py --device cpu --data "$TRAIN_FILE" --runs 16 --jobs 16 \
            --threads 1
        ;;
    more)
        on_device
        step more-flight 170 python3 benchmarks/bench_gpu.py --device cuda --engines ground-elsewhere \
            --batches 1024,262144 --parity-shots 1000 --share-rows 4194304 --sweep-rows 4194304 --torch-workers 2 \
            --sweep-timeout 40
        step more-train 90 python3 benchmarks/bench_train.py --device cuda --data "$TRAIN_FILE" --runs 1
        ;;
    *) echo "usage: bash scripts/gpu_session.sh prepare|flight|train|more" >&2; exit 2 ;;
esac
