// The OpenEXR functions linked into the library as an ExrCodec (exr_codec.hpp).
#include "hairlut/io/exr_codec.hpp"

#include "hairlut/io/engine_exr.hpp"

namespace hairlut {

ExrCodec linked_exr_codec() {
  ExrCodec codec;
  codec.write_exr = &write_exr;
  codec.write_engine_texture = &write_engine_texture;
  codec.read_exr = &read_exr;
  return codec;
}

}  // namespace hairlut
