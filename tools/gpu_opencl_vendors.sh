# Sourced, not run: opencl_vendors DIR makes DIR the OpenCL ICD loader's vendor folder (the
# system's vendor files, and one for NVIDIA's OpenCL library where the driver installed it
# without one, as in a container) and exports OCL_ICD_VENDORS=DIR. A bundle of
# tools/gpu_bundle.sh carries this file beside its run.sh; tools/gpu_equal_time.sh sources it
# from there.
opencl_vendors() {
  local vendors=$1 nvidia
  mkdir -p "$vendors"
  cp /etc/OpenCL/vendors/*.icd "$vendors/" 2>/dev/null || true
  nvidia=$(ldconfig -p 2>/dev/null | awk '$1 == "libnvidia-opencl.so.1" {print $NF; exit}')
  [ -n "$nvidia" ] || nvidia=$(find /usr/lib /usr/lib64 /usr/local/nvidia -name libnvidia-opencl.so.1 2>/dev/null | head -n 1)
  [ -n "$nvidia" ] && [ ! -e "$vendors/nvidia.icd" ] && echo "$nvidia" > "$vendors/nvidia.icd"
  export OCL_ICD_VENDORS="$vendors"
}
