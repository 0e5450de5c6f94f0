// image_error.cpp: the error measure of `make bench`'s time-to-quality rows
// (tests/bench/run.sh): the root-mean-square difference of two images over every pixel
// and the R, G and B channels, and each image's mean colour. `rtspheres diff` prints an
// RMS error too, but of each pixel's largest channel difference, and the bench measures
// renderers other than rtspheres: so a tool of its own, with OpenImageIO (already a
// dependency of rtspheres) reading rtspheres' and Blender's EXRs alike.
//
// usage: image_error IMAGE [REFERENCE]
//   prints "mean R G B" of IMAGE; with REFERENCE also "rmse E" and the reference's
//   "reference_mean R G B", on one line:
//   mean 0.1771 0.1584 0.1442 rmse 0.01602 reference_mean 0.1775 0.1588 0.1445
// The channels are found by name (R, G, B), else the first three are taken; other
// channels (alpha, rtspheres' samples) are ignored. The images must have the same size.
// Exit status: 0 done, 2 an image could not be read or the sizes differ.

#include <OpenImageIO/imagebuf.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;     // width * height * 3, rows from the top
};

// Reads PATH's R, G, B into IMAGE; returns false (with a message on stderr) on failure.
bool read_rgb(const char *path, Image &image)
{
    OIIO::ImageBuf buffer(path);
    if (!buffer.read(0, 0, true, OIIO::TypeDesc::FLOAT)) {
        std::fprintf(stderr, "image_error: cannot read %s: %s\n", path, buffer.geterror().c_str());
        return false;
    }
    const OIIO::ImageSpec &spec = buffer.spec();
    if (spec.nchannels < 3) {
        std::fprintf(stderr, "image_error: %s has fewer than 3 channels\n", path);
        return false;
    }
    int channels[3] = {spec.channelindex("R"), spec.channelindex("G"), spec.channelindex("B")};
    if (channels[0] < 0 || channels[1] < 0 || channels[2] < 0)
        channels[0] = 0, channels[1] = 1, channels[2] = 2;
    image.width = spec.width;
    image.height = spec.height;
    image.rgb.resize(static_cast<size_t>(spec.width) * spec.height * 3);
    std::vector<float> pixel(spec.nchannels);
    size_t at = 0;
    for (int y = spec.y; y < spec.y + spec.height; y++)
        for (int x = spec.x; x < spec.x + spec.width; x++) {
            buffer.getpixel(x, y, pixel.data(), spec.nchannels);
            for (int c = 0; c < 3; c++)
                image.rgb[at++] = pixel[channels[c]];
        }
    return true;
}

// Prints the mean of each channel of IMAGE after LABEL.
void print_mean(const char *label, const Image &image)
{
    double sum[3] = {0, 0, 0};
    for (size_t i = 0; i < image.rgb.size(); i++)
        sum[i % 3] += image.rgb[i];
    double count = static_cast<double>(image.rgb.size() / 3);
    std::printf("%s %.6g %.6g %.6g", label, sum[0] / count, sum[1] / count, sum[2] / count);
}

}  // namespace

int main(int argc, char **argv)
{
    if (argc != 2 && argc != 3) {
        std::fprintf(stderr, "usage: image_error IMAGE [REFERENCE]\n");
        return 2;
    }
    Image image, reference;
    if (!read_rgb(argv[1], image))
        return 2;
    print_mean("mean", image);
    if (argc == 3) {
        if (!read_rgb(argv[2], reference))
            return 2;
        if (reference.width != image.width || reference.height != image.height) {
            std::fprintf(stderr, "\nimage_error: %s is %dx%d, %s %dx%d\n", argv[1], image.width, image.height,
                         argv[2], reference.width, reference.height);
            return 2;
        }
        double squares = 0;
        for (size_t i = 0; i < image.rgb.size(); i++) {
            double d = static_cast<double>(image.rgb[i]) - reference.rgb[i];
            squares += d * d;
        }
        std::printf(" rmse %.6g", std::sqrt(squares / static_cast<double>(image.rgb.size())));
        print_mean(" reference_mean", reference);
    }
    std::printf("\n");
    return 0;
}
