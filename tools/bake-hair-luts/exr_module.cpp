// The baker's OpenEXR module (hairlut-exr.so): the library's OpenEXR writers and reader behind one
// C entry point, loaded by exr_loader.cpp only when a config asks for EXR files, so that a bake of
// HDF5 files never maps the OpenEXR libraries. Everything but the entry point is hidden.
#include <hairlut/io/exr_codec.hpp>

extern "C" __attribute__((visibility("default"))) void hairlut_exr_codec_v1(hairlut::ExrCodec* out) {
  *out = hairlut::linked_exr_codec();
}
