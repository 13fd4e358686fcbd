// Built without OpenImageIO (-DNEBULA_OPENIMAGEIO=OFF, or not found): the
// GPU nodes' configuration. write_image and read_image refuse .exr and .png
// before calling these; they are here so the library links.
#include "core/error.h"
#include "imageio/image_formats.h"

namespace nebula {

bool openimageio_available() { return false; }

Image read_any_image(const std::string& path) {
  throw Error(path + ": cannot read: this build has no OpenImageIO (configure with -DNEBULA_OPENIMAGEIO=ON); "
              "give the map as .h5 or .fits");
}

namespace imageio_detail {

namespace {
[[noreturn]] void no_openimageio(const char* what) {
  throw Error(std::string(what) + " needs OpenImageIO; this build has none (configure with "
              "-DNEBULA_OPENIMAGEIO=ON), use .h5 or .fits");
}
}  // namespace

void write_exr(const Image&, const ImageMetadata&, const std::string&) { no_openimageio(".exr output"); }
void write_png(const Image&, const ImageMetadata&, const std::string&) { no_openimageio(".png output"); }
Image read_exr(const std::string& path, ImageMetadata*) {
  throw Error(path + ": cannot read: .exr needs OpenImageIO; this build has none (configure with "
              "-DNEBULA_OPENIMAGEIO=ON)");
}

}  // namespace imageio_detail

}  // namespace nebula
