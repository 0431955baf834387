#!/usr/bin/env bash
# On a machine with an NVIDIA driver: the OpenCL driver folder that the
# micropoly_native wheel writes (native/python/micropoly_native/
# opencl_vendors.py) keeps the system's GPU driver beside the CPU device it
# adds. The driver is registered as its package does (/etc/OpenCL/vendors/
# nvidia.icd), in a private mount namespace so the machine is left as it
# was; an empty file laid out as the micropoly_pocl wheel installs its
# library stands in for the carried PoCL (the loader skips it: the carried
# PoCL itself is tested on the CPU by tests/packaging/test_extension.py). The
# CLI then lists and renders on the devices the loader finds there.
#   tests/packaging/device_gpu_check.sh CLI [DRIVER]
set -euo pipefail
cli=$(realpath "$1")
driver=${2:-/usr/lib/libnvidia-opencl.so}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
mkdir -p "$work/site/micropoly_pocl/lib/x86_64-linux-gnu"
touch "$work/site/micropoly_pocl/__init__.py"
touch "$work/site/micropoly_pocl/lib/x86_64-linux-gnu/libpocl.so.2"
mkdir -p /etc/OpenCL/vendors
unshare -m --propagation private sh -c "
  mount -t tmpfs none /etc/OpenCL/vendors &&
  echo '$driver' > /etc/OpenCL/vendors/nvidia.icd &&
  export HOME='$work' && unset OCL_ICD_VENDORS &&
  eval \$(PYTHONPATH='$work/site' python3 -c '
import importlib.util, sys
spec = importlib.util.spec_from_file_location(\"v\", \"$here/../../native/python/micropoly_native/opencl_vendors.py\")
v = importlib.util.module_from_spec(spec); spec.loader.exec_module(v)
added = v.register()
import os
print(\"export OCL_ICD_VENDORS=\" + os.environ.get(\"OCL_ICD_VENDORS\", \"\") + \";\")
print(\"echo carried device: \" + str(added))
') &&
  ls \$OCL_ICD_VENDORS && '$cli' --list-devices &&
  '$cli' '$here/../scenes/teapot.rib' -o '$work/teapot.png' --device gpu --spp 16 --stats '$work/stats.json' > /dev/null &&
  echo rendered on the GPU: && grep -o '\"device\": *\"[^\"]*\"' '$work/stats.json'"
