# Sourced by the bundle's benchmark scripts (bench/make_device_bundle.sh):
# the bundled libraries, and on a GPU machine NVIDIA's OpenCL driver, which
# is installed there but not registered; writes the device to $OUT/device.txt.
export LD_LIBRARY_PATH=$PWD/lib
if [ "$DEVICE" = gpu ]; then
  mkdir -p /tmp/icd && echo /usr/lib/libnvidia-opencl.so > /tmp/icd/nvidia.icd
  export OCL_ICD_VENDORS=/tmp/icd MICROPOLY_CACHE_DIR=/tmp/mpcache
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/device.txt"
fi
./micropoly-render --list-devices | tee -a "$OUT/device.txt"
