# Sourced in the bundle's folder before its runs (bench/make_device_bundle.sh,
# docs/performance.md): the bundled libraries, and with DEVICE=gpu (the
# default) NVIDIA's OpenCL driver, which is installed there but not
# registered; writes the device to $OUT/device.txt (OUT: /tmp/bench).
DEVICE=${DEVICE:-gpu}
OUT=${OUT:-/tmp/bench}
mkdir -p "$OUT"
export LD_LIBRARY_PATH=$PWD/lib
if [ "$DEVICE" = gpu ]; then
  mkdir -p /tmp/icd && echo /usr/lib/libnvidia-opencl.so > /tmp/icd/nvidia.icd
  export OCL_ICD_VENDORS=/tmp/icd MICROPOLY_CACHE_DIR=/tmp/mpcache
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/device.txt"
fi
./micropoly-render --list-devices | tee -a "$OUT/device.txt"
