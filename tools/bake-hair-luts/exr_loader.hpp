// The OpenEXR code for the baker: none when the config writes no EXR file, otherwise the
// functions of the module hairlut-exr.so (exr_module.cpp), looked up beside the executable (build
// tree) and then in the installed module directory.
#pragma once

#include <hairlut/bake/config.hpp>
#include <hairlut/io/exr_codec.hpp>

namespace hairlut_tools {

/// The codec `config` needs: empty when it writes no EXR file. Throws hairlut::IoError naming
/// the module when it cannot be loaded.
hairlut::ExrCodec exr_codec_for(const hairlut::BakeConfig& config);

}  // namespace hairlut_tools
