/* image_io.cpp: see image_io.h. A thin extern "C" shim over OpenImageIO (obj_load.cpp and
 * image_diff.cpp are the other C++ files). No C++ exception crosses the C boundary; every
 * entry point catches them.
 *
 * Pixels go through OpenImageIO: an rt_image is wrapped as an ImageBuf (wrap()), exposure
 * and clamping are ImageBufAlgo::mul and ::clamp, a gamma is ::pow, the channels of HDR
 * and of image_append_channels() are ::channels and ::channel_append, and 8-bit files are
 * quantised by OIIO as it writes them. Only the sRGB and BT.709 curves are written out
 * here (see srgb_encode() for why not ::colorconvert).
 *
 * Writing encodes the file into memory first (through an OIIO IOProxy) and then writes the
 * bytes to the temporary file itself, so every disk error is seen here with its errno:
 * libjpeg, for one, calls exit() on a write error when it owns the file. TIFF is the
 * exception: OIIO 2.4's TIFF writer produces a corrupt file through an IOProxy as soon as
 * it writes an EXIF block (which "oiio:ColorSpace" = "sRGB" does), so OIIO writes TIFF to
 * the temporary file directly; libtiff reports write errors properly.
 */
#include "image_io.h"
#include "large_pages.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcntl.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

namespace {

enum class file_kind { unknown, exr, hdr, eight_bit };

const char *const supported_extensions = ".exr .hdr .png .jpg .jpeg .tif .tiff";

/* Returns the extension of path's last component including the dot ("" when none), so
 * the temporary file can end the same way and OIIO picks the same format for it. */
std::string extension_of(const std::string &path)
{
    size_t slash = path.find_last_of('/');
    size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
        return "";
    return path.substr(dot);
}

/* Returns how a file with this extension is written. */
file_kind kind_of_extension(const std::string &extension)
{
    const char *e = extension.c_str();
    if (strcasecmp(e, ".exr") == 0)
        return file_kind::exr;
    if (strcasecmp(e, ".hdr") == 0)
        return file_kind::hdr;
    for (const char *eight_bit : {".png", ".jpg", ".jpeg", ".tif", ".tiff"})
        if (strcasecmp(e, eight_bit) == 0)
            return file_kind::eight_bit;
    return file_kind::unknown;
}

/* Returns the name channel c of image goes by: its own, or the documented default. */
std::string channel_name(const rt_image *image, int c)
{
    if (image->channel_names[c][0] != '\0')
        return std::string(image->channel_names[c],
                           strnlen(image->channel_names[c], IMAGE_CHANNEL_NAME_MAX));
    static const char *const rgba[] = {"R", "G", "B", "A"};
    if (c < 4)
        return rgba[c];
    return "channel" + std::to_string(c);
}

/* Whether a channel of this name holds alpha, which 8-bit outputs write linearly. */
bool is_alpha_name(const std::string &name)
{
    return strcasecmp(name.c_str(), "A") == 0 || strcasecmp(name.c_str(), "Alpha") == 0;
}

/* OIIO sometimes ends its messages with a newline, and some failures (a truncated PPM)
 * come with no message at all; ours are one line and never empty. */
std::string one_line(std::string message, const char *if_empty = "unknown error")
{
    while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
        message.pop_back();
    for (char &ch : message)
        if (ch == '\n')
            ch = ' ';
    return message.empty() ? if_empty : message;
}

/* The ImageSpec of image's float pixels: its size and channel names, and OIIO's alpha
 * channel the first channel named as alpha (is_alpha_name()). */
OIIO::ImageSpec float_spec(const rt_image *image)
{
    OIIO::ImageSpec spec(image->width, image->height, image->channels, OIIO::TypeDesc::FLOAT);
    spec.alpha_channel = -1;
    for (int c = 0; c < image->channels; c++) {
        spec.channelnames[c] = channel_name(image, c);
        if (spec.alpha_channel < 0 && is_alpha_name(spec.channelnames[c]))
            spec.alpha_channel = c;
    }
    return spec;
}

/* An ImageBuf over image's pixels, neither copied nor owned; OIIO writes into them only
 * when asked to (decode_to_linear()). */
OIIO::ImageBuf wrap(const rt_image *image)
{
    return OIIO::ImageBuf(float_spec(image), image->pixels);
}

/* Throws OIIO's message when an ImageBufAlgo step failed (it returns false, or an
 * ImageBuf with an error). */
void check(bool ok, const OIIO::ImageBuf &result)
{
    if (!ok || result.has_error())
        throw std::runtime_error(one_line(result.geterror(), "OpenImageIO could not convert the pixels"));
}

/* The channels of an image with this spec that hold colour: all but alpha (by name, or
 * the spec's alpha channel) and depth. */
std::vector<int> colour_channels(const OIIO::ImageSpec &spec)
{
    std::vector<int> colour;
    for (int c = 0; c < spec.nchannels; c++)
        if (c != spec.alpha_channel && c != spec.z_channel && !is_alpha_name(spec.channelnames[c]))
            colour.push_back(c);
    return colour;
}

/* The sRGB (IEC 61966-2-1) and BT.709 transfer functions, written out rather than taken
 * from ImageBufAlgo::colorconvert: OpenImageIO 2.4 without an OCIO config uses its
 * built-in curves, which approximate pow (fast_pow_pos). Measured against these: sRGB
 * encoding is off by up to 7.3e-6, which moves 0.05% of 8-bit codes by one (a pixel of the
 * refcheck's --tonemap aces PNG); sRGB decoding by up to 5.9e-6 and BT.709 decoding by up
 * to 1.2e-7, which the environment map's importance sampling turns into render
 * differences up to 6e-4 (scenes/environment.txt, tests/render/scenes/loop-stress.txt,
 * whose sky is a PPM). A gamma is a plain power: ImageBufAlgo::pow, exact. */
float srgb_encode(float linear)
{
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float value)
{
    return value <= 0.04045f ? value / 12.92f : std::pow((value + 0.055f) / 1.055f, 2.4f);
}

float rec709_decode(float value)
{
    return value < 0.081f ? value / 4.5f : std::pow((value + 0.099f) / 1.099f, 1.0f / 0.45f);
}

/* Applies a transfer function to the listed channels of image (float pixels in memory),
 * in place. */
void apply_transfer(OIIO::ImageBuf &image, const std::vector<int> &channels, float (*transfer)(float))
{
    float *pixels = (float *)image.localpixels();
    if (pixels == nullptr || image.spec().format != OIIO::TypeDesc::FLOAT)
        throw std::runtime_error("the pixels to convert are not floats in memory");
    const size_t count = image.spec().image_pixels();
    const int stride = image.nchannels();
    for (size_t p = 0; p < count; p++)
        for (int c : channels)
            pixels[p * stride + c] = transfer(pixels[p * stride + c]);
}

/* The pixels of an 8-bit file, still as floats (OIIO rounds them when it writes): colour
 * scaled by 2^exposure, everything clamped to [0,1] (NaN becomes 0), colour sRGB-encoded.
 * Alpha is coverage, so it is neither exposed nor encoded. */
OIIO::ImageBuf eight_bit_pixels(const rt_image *image, float exposure)
{
    OIIO::ImageBuf source = wrap(image);
    std::vector<int> colour = colour_channels(source.spec());
    std::vector<float> gain(image->channels, 1.0f);
    for (int c : colour)
        gain[c] = std::exp2(exposure);
    OIIO::ImageBuf out = OIIO::ImageBufAlgo::mul(source, gain);
    check(out.initialized(), out);
    std::vector<float> low(image->channels, 0.0f), high(image->channels, 1.0f);
    check(OIIO::ImageBufAlgo::clamp(out, out, low, high), out);
    apply_transfer(out, colour, srgb_encode);
    return out;
}

/* Adds the caller's metadata to spec. OpenEXR has no 64-bit integer attribute (OIIO
 * silently drops one), so integers beyond 32 bits are stored as their decimal text. */
void add_attributes(OIIO::ImageSpec &spec, const image_write_options *options)
{
    for (int i = 0; i < options->attribute_count; i++) {
        const image_attribute &attribute = options->attributes[i];
        if (attribute.name == nullptr || attribute.name[0] == '\0')
            continue;
        switch (attribute.type) {
        case IMAGE_ATTRIBUTE_STRING:
            spec.attribute(attribute.name, attribute.string_value ? attribute.string_value : "");
            break;
        case IMAGE_ATTRIBUTE_INT:
            if (attribute.int_value >= INT_MIN && attribute.int_value <= INT_MAX)
                spec.attribute(attribute.name, (int)attribute.int_value);
            else
                spec.attribute(attribute.name, std::to_string(attribute.int_value));
            break;
        case IMAGE_ATTRIBUTE_FLOAT:
            spec.attribute(attribute.name, OIIO::TypeDesc::DOUBLE, &attribute.float_value);
            break;
        }
    }
}

/* Whether OIIO's writer for this format works through an in-memory IOProxy (see top). */
bool encodes_in_memory(const std::string &extension)
{
    const char *e = extension.c_str();
    return strcasecmp(e, ".tif") != 0 && strcasecmp(e, ".tiff") != 0;
}

/* The pixels written for image in a file of this kind, as floats: 8-bit files'
 * (eight_bit_pixels()), Radiance HDR's RGB (the first three channels, or a grey one
 * thrice), an EXR's as they are. Every step is per pixel, so a band of rows converts
 * to the rows of the whole image's conversion. */
OIIO::ImageBuf pixels_for_kind(file_kind kind, const rt_image *image, float exposure)
{
    if (kind == file_kind::eight_bit)
        return eight_bit_pixels(image, exposure);
    if (kind == file_kind::hdr) {
        OIIO::ImageBuf pixels =
            image->channels >= 3 ? OIIO::ImageBufAlgo::channels(wrap(image), 3, {0, 1, 2}, {}, {"R", "G", "B"})
                                 : OIIO::ImageBufAlgo::channels(wrap(image), 3, {0, 0, 0}, {}, {"R", "G", "B"});
        check(pixels.initialized(), pixels);
        return pixels;
    }
    return wrap(image);
}

/* The spec of a file of this kind holding pixels (pixels_for_kind()'s, of height rows:
 * the whole image's, a band may be shorter) of image: 8-bit files quantised by OIIO as it
 * writes, an EXR's place in the full image, the colour space and the caller's metadata. */
OIIO::ImageSpec spec_for_kind(file_kind kind, const OIIO::ImageSpec &pixels, int height, const rt_image *image,
                              const image_write_options *options)
{
    OIIO::ImageSpec spec = pixels;
    spec.height = height;
    spec.full_height = height;
    if (kind == file_kind::eight_bit)
        spec.set_format(OIIO::TypeDesc::UINT8);
    /* A crop or tile of a larger image keeps its place: EXR stores it as the data window
     * inside the display window; other formats just get the pixels. */
    if (kind == file_kind::exr && image->full_width > 0 && image->full_height > 0) {
        spec.x = image->x;
        spec.y = image->y;
        spec.full_x = 0;
        spec.full_y = 0;
        spec.full_width = image->full_width;
        spec.full_height = image->full_height;
    }
    spec.attribute("oiio:ColorSpace", kind == file_kind::eight_bit ? "sRGB" : "Linear");
    /* EXR: PIZ, lossless like OpenEXR's default ZIP, but it writes renders' noisy floats in
     * about half of ZIP's time and mostly smaller (docs/performance.md, the log). */
    if (kind == file_kind::exr)
        spec.attribute("compression", EXR_COMPRESSION);
    /* OIIO takes pixels to be premultiplied and would divide the (already sRGB-encoded)
     * colour by alpha for PNG; the header promises the values are stored as given. */
    if (kind == file_kind::eight_bit)
        spec.attribute("oiio:UnassociatedAlpha", 1);
    add_attributes(spec, options);
    return spec;
}

/* Has OIIO write image as the format of format_path: into bytes when memory is not null,
 * else into the file file_path (which is also the name OIIO's messages use). Returns ""
 * on success, else OIIO's message. */
std::string encode(const std::string &format_path, const char *file_path, file_kind kind,
                   const rt_image *image, const image_write_options *options,
                   OIIO::Filesystem::IOVecOutput *memory)
{
    auto output = OIIO::ImageOutput::create(format_path, memory);
    if (!output)
        return one_line(OIIO::geterror());
    if (memory != nullptr && !output->supports("ioproxy"))
        return "the OpenImageIO plugin for this format cannot write to memory";
    OIIO::ImageBuf pixels = pixels_for_kind(kind, image, options->exposure);
    OIIO::ImageSpec spec = spec_for_kind(kind, pixels.spec(), image->height, image, options);
    if (!output->open(file_path, spec))
        return one_line(output->geterror());
    if (!output->write_image(OIIO::TypeDesc::FLOAT, pixels.localpixels())) {
        std::string message = one_line(output->geterror());
        output->close();
        return message;
    }
    if (!output->close())
        return one_line(output->geterror());
    if (memory != nullptr && memory->size() == 0)
        return "OpenImageIO produced no data";
    return "";
}

/* Writes all of bytes to fd. Returns 0, or an errno value. */
int write_all(int fd, const std::vector<unsigned char> &bytes)
{
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return errno;
        }
        done += (size_t)n;
    }
    return 0;
}

/* The mode a newly created file would get: mkstemps makes 0600 files, which would be a
 * surprise after the rename. umask() can only be read by setting it; it is restored at
 * once (the window only matters to another thread creating a file at the same moment). */
mode_t new_file_mode()
{
    mode_t mask = umask(022);
    umask(mask);
    return 0666 & ~mask;
}

/* Flushes the directory entry of the rename too; failures are harmless and ignored. */
void sync_directory(const std::string &directory)
{
    int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        fsync(fd);
        ::close(fd);
    }
}

/* Sets the error for a write that failed for reason why; returns RT_ERROR_RUNTIME. */
rt_status write_failed(rt_error *error, const char *path, const std::string &why)
{
    return rt_error_set(error, RT_ERROR_RUNTIME, "IMAGE: cannot write '%s': %s", path,
                        why.c_str());
}

/* Returns the mkstemps() template of destination's temporary file (".NAME.tmp-XXXXXX"
 * and the extension, in its directory, NUL-terminated) and sets directory to the
 * directory. */
std::vector<char> temporary_template(const std::string &destination, const std::string &extension,
                                     std::string &directory)
{
    size_t slash = destination.find_last_of('/');
    std::string prefix = slash == std::string::npos ? "" : destination.substr(0, slash + 1);
    std::string base = destination.substr(prefix.size());
    directory = prefix.empty() ? "." : prefix.size() == 1 ? "/" : prefix.substr(0, prefix.size() - 1);
    std::string temporary = prefix + "." + base + ".tmp-XXXXXX" + extension;
    std::vector<char> name(temporary.begin(), temporary.end());
    name.push_back('\0');
    return name;
}

/* Writes image to a temporary file next to path and renames it over path. On failure the
 * temporary file is removed and path is untouched. */
rt_status image_write_impl(const char *path, const rt_image *image,
                           const image_write_options *options, rt_error *error)
{
    const std::string destination = path;
    const std::string extension = extension_of(destination);
    file_kind kind = kind_of_extension(extension);
    if (kind == file_kind::unknown) {
        if (extension.empty())
            return rt_error_set(error, RT_ERROR_INPUT,
                                "IMAGE: cannot write '%s': no file extension to pick the format by "
                                "(supported: %s)", path, supported_extensions);
        return rt_error_set(error, RT_ERROR_INPUT,
                            "IMAGE: cannot write '%s': unknown extension '%s' (supported: %s)",
                            path, extension.c_str(), supported_extensions);
    }
    if (image == nullptr || image->pixels == nullptr || image->width <= 0 || image->height <= 0
        || image->channels <= 0 || image->channels > IMAGE_MAX_CHANNELS)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "IMAGE: cannot write '%s': not a valid image (%dx%d, %d channels%s)",
                            path, image ? image->width : 0, image ? image->height : 0,
                            image ? image->channels : 0,
                            image && image->pixels == nullptr ? ", no pixels" : "");
    image_write_options defaults = image_write_options_defaults();
    if (options == nullptr)
        options = &defaults;

    std::string directory;
    std::vector<char> temporary_name = temporary_template(destination, extension, directory);

    int fd = mkstemps(temporary_name.data(), (int)extension.size());
    if (fd < 0)
        return write_failed(error, path, std::string("cannot create a temporary file in '")
                                             + directory + "': " + strerror(errno));
    const char *temporary_path = temporary_name.data();

    std::string failure;
    try {
        std::vector<unsigned char> bytes;
        bool in_memory = encodes_in_memory(extension);
        if (in_memory) {
            /* Room for the pixels as floats (what an EXR holds at most, about) up front, on
             * huge pages: growing the vector by doubling copies it and touches fresh memory
             * each time, which is slow (core/large_pages.h); 60 ms of a 1200x675 EXR. */
            bytes.reserve((size_t)image->width * image->height * image->channels * sizeof(float) + 65536);
            large_pages_advise(bytes.data(), bytes.capacity());
        }
        OIIO::Filesystem::IOVecOutput memory(bytes);
        failure = encode(destination, temporary_path, kind, image, options,
                         in_memory ? &memory : nullptr);
        if (failure.empty()) {
            int err = in_memory ? write_all(fd, bytes) : 0;
            if (err == 0 && fsync(fd) != 0 && errno != EINVAL)
                err = errno;
            if (err == 0 && fchmod(fd, new_file_mode()) != 0)
                err = errno;
            if (err != 0)
                failure = strerror(err);
        }
    } catch (const std::bad_alloc &) {
        failure = "out of memory";
    } catch (const std::exception &e) {
        failure = one_line(e.what());
    } catch (...) {
        failure = "unexpected C++ exception";
    }
    if (::close(fd) != 0 && failure.empty())
        failure = strerror(errno);
    if (failure.empty() && rename(temporary_path, path) != 0)
        failure = std::string("cannot rename the temporary file over it: ") + strerror(errno);
    if (!failure.empty()) {
        unlink(temporary_path);
        return write_failed(error, path, failure);
    }
    sync_directory(directory);
    return RT_OK;
}

/* Sets the error for a read that failed for reason why; returns RT_ERROR_INPUT. */
rt_status read_failed(rt_error *error, const char *path, const std::string &why)
{
    return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: cannot read '%s': %s", path,
                        why.c_str());
}

/* Opens path for reading. Returns nullptr with the error set when that fails. OIIO's own
 * message for a missing file is vague, so that case is reported from errno. */
std::unique_ptr<OIIO::ImageInput> open_input(const char *path, rt_error *error)
{
    struct stat info;
    if (stat(path, &info) != 0) {
        read_failed(error, path, strerror(errno));
        return nullptr;
    }
    if (S_ISDIR(info.st_mode)) {
        read_failed(error, path, "it is a directory");
        return nullptr;
    }
    if (info.st_size == 0) {
        read_failed(error, path, "the file is empty");
        return nullptr;
    }
    /* Without this OIIO multiplies PNG colour by alpha; we return what the file stores. */
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto input = OIIO::ImageInput::open(path, &config);
    if (!input)
        read_failed(error, path,
                    one_line(OIIO::geterror(), "not an image file OpenImageIO reads"));
    return input;
}

/* How a file's colour channels are encoded: a transfer function to decode with (none for
 * linear) or a gamma; see image_read_linear() in image_io.h. */
struct encoding {
    float (*decode)(float) = nullptr;
    float gamma = 0.0f;
};

/* Returns how the colour channels of a file with this spec are encoded. */
encoding encoding_of(const OIIO::ImageSpec &spec)
{
    encoding e;
    /* Floating-point pixels hold light itself, whatever the label: OpenImageIO calls
     * every PFM "Rec709", and decoding a value of 2000 with a display curve gives 2e7. */
    if (spec.format.is_floating_point())
        return e;
    std::string space = spec.get_string_attribute("oiio:ColorSpace");
    const char *name = space.c_str();
    if (strcasecmp(name, "Rec709") == 0) {
        e.decode = rec709_decode;
    } else if (strncasecmp(name, "GammaCorrected", 14) == 0) {
        char *end = nullptr;
        double g = strtod(name + 14, &end);
        e.gamma = end != name + 14 && std::isfinite(g) && g > 0 ? (float)g : 2.2f;
    } else if (strcasecmp(name, "Linear") != 0 && strcasecmp(name, "scene_linear") != 0) {
        e.decode = srgb_decode;  /* "sRGB", or no or another name on an integer file */
    }
    return e;
}

/* Converts the colour channels of out (read with spec) to linear light, in place; alpha
 * and depth channels are kept as stored. */
void decode_to_linear(const OIIO::ImageSpec &spec, rt_image *out)
{
    encoding e = encoding_of(spec);
    OIIO::ImageSpec named = float_spec(out);  /* the names as read, the file's alpha and depth */
    named.alpha_channel = spec.alpha_channel;
    named.z_channel = spec.z_channel;
    std::vector<int> colour = colour_channels(named);
    OIIO::ImageBuf image = wrap(out);
    if (e.decode != nullptr) {
        apply_transfer(image, colour, e.decode);
    } else if (e.gamma > 0) {
        std::vector<float> exponent(out->channels, 1.0f);
        for (int c : colour)
            exponent[c] = e.gamma;
        check(OIIO::ImageBufAlgo::pow(image, image, exponent), image);
    }
}

/* An image file's bytes in memory (image_read_memory), read through an IOProxy. */
struct memory_file {
    const void *bytes;
    size_t size;
};

/* Opens the image file in memory, which messages call name. OpenImageIO picks a reader by
 * the name's extension (trying the others when that one fails), so the name it is given
 * says what the first bytes say: PNG or JPEG, the formats glTF files embed. */
std::unique_ptr<OIIO::ImageInput> open_memory_input(const char *name, const memory_file &memory,
                                                    OIIO::Filesystem::IOMemReader *proxy, rt_error *error)
{
    if (memory.bytes == nullptr || memory.size == 0) {
        read_failed(error, name, "the image is empty");
        return nullptr;
    }
    const unsigned char *b = (const unsigned char *)memory.bytes;
    bool jpeg = memory.size >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF;
    /* OpenImageIO 2.4 ignores open()'s proxy argument when a config is given: the proxy
     * goes in the config ("oiio:ioproxy", a pointer). */
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    void *proxy_pointer = proxy;
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_pointer);
    auto input = OIIO::ImageInput::open(jpeg ? "memory.jpg" : "memory.png", &config);
    if (!input)
        read_failed(error, name, one_line(OIIO::geterror(), "not an image file OpenImageIO reads"));
    return input;
}

/* Reads path (or the file in memory, when memory is not nullptr; path then names it) into
 * *out, which the caller has zeroed and frees on an exception. Images wider or taller
 * than max_side (when > 0) are refused before their pixels are read; linear asks for
 * decode_to_linear(). */
rt_status image_read_impl(const char *path, int max_side, bool linear, rt_image *out,
                          rt_error *error, const memory_file *memory = nullptr)
{
    std::unique_ptr<OIIO::Filesystem::IOMemReader> proxy;
    if (memory != nullptr)
        proxy.reset(new OIIO::Filesystem::IOMemReader((void *)memory->bytes, memory->size));
    auto input = memory != nullptr ? open_memory_input(path, *memory, proxy.get(), error)
                                   : open_input(path, error);
    if (!input)
        return RT_ERROR_INPUT;
    const OIIO::ImageSpec &spec = input->spec();
    if (spec.deep)
        return read_failed(error, path, "deep images are not supported");
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        return read_failed(error, path, "the image has no pixels");
    if (max_side > 0 && (spec.width > max_side || spec.height > max_side))
        return read_failed(error, path,
                           "it is " + std::to_string(spec.width) + "x" + std::to_string(spec.height)
                               + " pixels, more than " + std::to_string(max_side) + " on a side");
    if (spec.nchannels > IMAGE_MAX_CHANNELS)
        return read_failed(error, path,
                           "it has " + std::to_string(spec.nchannels) + " channels; at most "
                               + std::to_string(IMAGE_MAX_CHANNELS) + " are supported");

    rt_status status = image_create(out, spec.width, spec.height, spec.nchannels, error);
    if (status != RT_OK)
        return status;
    for (int c = 0; c < spec.nchannels && c < (int)spec.channelnames.size(); c++)
        snprintf(out->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s",
                 spec.channelnames[c].c_str());
    out->x = spec.x - spec.full_x;
    out->y = spec.y - spec.full_y;
    out->full_width = spec.full_width;
    out->full_height = spec.full_height;
    if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, out->pixels)) {
        image_free(out);
        return read_failed(error, path,
                           one_line(input->geterror(), "the file is truncated or corrupt"));
    }
    if (linear)
        decode_to_linear(spec, out);
    input->close();
    return RT_OK;
}

/* Formats value with the fewest significant digits that read back as the same number. */
std::string shortest_text(double value, bool single_precision)
{
    char text[64];
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, value);
        bool same = single_precision ? strtof(text, nullptr) == (float)value
                                     : strtod(text, nullptr) == value;
        if (same)
            break;
    }
    return text;
}

/* Returns an attribute's value as text: numbers plainly, strings as they are. */
std::string attribute_text(const OIIO::ParamValue &parameter)
{
    OIIO::TypeDesc type = parameter.type();
    bool scalar = parameter.nvalues() == 1 && type.aggregate == OIIO::TypeDesc::SCALAR
                  && type.arraylen == 0;
    if (scalar) {
        if (type == OIIO::TypeDesc::STRING)
            return parameter.get_string();
        if (type.basetype == OIIO::TypeDesc::DOUBLE)
            return shortest_text(*(const double *)parameter.data(), false);
        if (type.basetype == OIIO::TypeDesc::FLOAT || type.basetype == OIIO::TypeDesc::HALF)
            return shortest_text(parameter.get_float(), true);
        if (type.basetype == OIIO::TypeDesc::INT64)
            return std::to_string(*(const long long *)parameter.data());
        if (type.basetype == OIIO::TypeDesc::UINT64)
            return std::to_string(*(const unsigned long long *)parameter.data());
        if (type.basetype == OIIO::TypeDesc::UINT32)
            return std::to_string(*(const unsigned int *)parameter.data());
        if (!type.is_floating_point())
            return std::to_string(parameter.get_int());
    }
    return parameter.get_string();
}

/* Reads attribute name of path as text into value; see image_read_attribute(). */
rt_status image_read_attribute_impl(const char *path, const char *name, char *value,
                                    int value_size, rt_error *error)
{
    if (name == nullptr || value == nullptr || value_size <= 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "IMAGE: reading an attribute of '%s' needs a name and a buffer", path);
    value[0] = '\0';
    auto input = open_input(path, error);
    if (!input)
        return RT_ERROR_INPUT;
    const OIIO::ParamValue *parameter =
        input->spec().find_attribute(name, OIIO::TypeDesc::UNKNOWN, true);
    if (parameter == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: '%s' has no attribute '%s'", path,
                            name);
    snprintf(value, (size_t)value_size, "%s", attribute_text(*parameter).c_str());
    return RT_OK;
}

/* Reads path's attributes named prefix... into *out; see image_read_attributes(). */
rt_status read_attributes_impl(const char *path, const char *prefix, image_attribute_set *out, rt_error *error)
{
    auto input = open_input(path, error);
    if (!input)
        return RT_ERROR_INPUT;
    size_t prefix_length = strlen(prefix);
    for (const OIIO::ParamValue &parameter : input->spec().extra_attribs) {
        std::string name = parameter.name().string();
        if (name.compare(0, prefix_length, prefix) != 0)
            continue;
        OIIO::TypeDesc type = parameter.type();
        bool scalar = parameter.nvalues() == 1 && type.aggregate == OIIO::TypeDesc::SCALAR && type.arraylen == 0;
        std::string text = attribute_text(parameter);
        image_attribute attribute = {name.c_str(), IMAGE_ATTRIBUTE_STRING, text.c_str(), 0, 0.0};
        if (scalar && type.basetype == OIIO::TypeDesc::INT32) {
            attribute = {name.c_str(), IMAGE_ATTRIBUTE_INT, nullptr, parameter.get_int(), 0.0};
        } else if (scalar && type.basetype == OIIO::TypeDesc::DOUBLE) {
            attribute = {name.c_str(), IMAGE_ATTRIBUTE_FLOAT, nullptr, 0, *(const double *)parameter.data()};
        } else if (scalar && (type.basetype == OIIO::TypeDesc::FLOAT || type.basetype == OIIO::TypeDesc::HALF)) {
            attribute = {name.c_str(), IMAGE_ATTRIBUTE_FLOAT, nullptr, 0, (double)parameter.get_float()};
        }
        rt_status status = image_attribute_set_put(out, &attribute, error);
        if (status != RT_OK) {
            image_attribute_set_free(out);
            return status;
        }
    }
    return RT_OK;
}

/* image_read() and image_read_linear(): reads path with image_read_impl(), turning every C++
 * exception into a status; on failure out is freed and zeroed. */
rt_status image_read_guarded(const char *path, int max_side, bool linear, rt_image *out,
                             rt_error *error)
{
    memset(out, 0, sizeof *out);
    if (path == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: no path to read an image from");
    try {
        return image_read_impl(path, max_side, linear, out, error);
    } catch (const std::bad_alloc &) {
        image_free(out);
        return rt_error_set(error, RT_ERROR_RUNTIME, "IMAGE: cannot read '%s': out of memory",
                            path);
    } catch (const std::exception &e) {
        image_free(out);
        return read_failed(error, path, one_line(e.what()));
    } catch (...) {
        image_free(out);
        return read_failed(error, path, "unexpected C++ exception");
    }
}

}  // namespace

/* A file being written band by band (image_stream_open()). */
struct image_stream {
    std::string destination, directory, temporary;
    file_kind kind = file_kind::unknown;
    std::unique_ptr<OIIO::ImageOutput> output;
    rt_image layout{};           /* size, channels, names and place; no pixels */
    float exposure = 0;
    int next_row = 0;
};

namespace {

/* Ends stream: closes its output, removes the temporary file and frees it. */
void abandon_stream(image_stream *stream)
{
    if (stream->output)
        stream->output->close();
    if (!stream->temporary.empty())
        unlink(stream->temporary.c_str());
    delete stream;
}

/* The body of image_stream_open(). */
rt_status open_stream(const char *path, const rt_image *layout, const image_write_options *options,
                      image_stream **out, rt_error *error)
{
    const std::string destination = path;
    const std::string extension = extension_of(destination);
    file_kind kind = kind_of_extension(extension);
    if (kind == file_kind::unknown)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: cannot write '%s': unknown extension '%s' (supported: %s)",
                            path, extension.c_str(), supported_extensions);
    if (layout->width <= 0 || layout->height <= 0 || layout->channels <= 0 || layout->channels > IMAGE_MAX_CHANNELS)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: cannot write '%s': not a valid image (%dx%d, %d channels)",
                            path, layout->width, layout->height, layout->channels);
    image_write_options defaults = image_write_options_defaults();
    if (options == nullptr)
        options = &defaults;
    std::unique_ptr<image_stream> stream(new image_stream);
    stream->destination = destination;
    stream->kind = kind;
    stream->layout = *layout;
    stream->layout.pixels = nullptr;
    stream->exposure = options->exposure;
    std::vector<char> name = temporary_template(destination, extension, stream->directory);
    int fd = mkstemps(name.data(), (int)extension.size());
    if (fd < 0)
        return write_failed(error, path, std::string("cannot create a temporary file in '") + stream->directory
                                             + "': " + strerror(errno));
    stream->temporary = name.data();
    /* OIIO writes the file itself (a band at a time cannot go through memory): the
     * descriptor only reserved the name and gives the file its mode. */
    int mode_error = fchmod(fd, new_file_mode()) != 0 ? errno : 0;
    ::close(fd);
    if (mode_error != 0) {
        unlink(stream->temporary.c_str());
        return write_failed(error, path, strerror(mode_error));
    }
    /* The spec of the converted pixels, from a one-row stand-in of the layout. */
    rt_image row = stream->layout;
    row.height = 1;
    std::vector<float> zeros((size_t)row.width * row.channels);
    row.pixels = zeros.data();
    OIIO::ImageBuf converted = pixels_for_kind(kind, &row, options->exposure);
    OIIO::ImageSpec spec = spec_for_kind(kind, converted.spec(), layout->height, layout, options);
    stream->output = OIIO::ImageOutput::create(destination);
    std::string failure = !stream->output ? one_line(OIIO::geterror()) : "";
    if (failure.empty() && !stream->output->open(stream->temporary, spec))
        failure = one_line(stream->output->geterror());
    if (!failure.empty()) {
        stream->output.reset();
        abandon_stream(stream.release());
        return write_failed(error, path, failure);
    }
    *out = stream.release();
    return RT_OK;
}

}  // namespace

extern "C" {

rt_status image_stream_open(const char *path, const rt_image *layout, const image_write_options *options,
                            image_stream **out, rt_error *error)
{
    *out = nullptr;
    if (path == nullptr || layout == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: no path or image to write");
    try {
        return open_stream(path, layout, options, out, error);
    } catch (const std::bad_alloc &) {
        return write_failed(error, path, "out of memory");
    } catch (const std::exception &e) {
        return write_failed(error, path, one_line(e.what()));
    } catch (...) {
        return write_failed(error, path, "unexpected C++ exception");
    }
}

rt_status image_stream_write_rows(image_stream *stream, const rt_image *rows, rt_error *error)
{
    const char *path = stream->destination.c_str();
    if (rows->width != stream->layout.width || rows->channels != stream->layout.channels || rows->height <= 0
        || stream->next_row + rows->height > stream->layout.height)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "IMAGE: cannot write '%s': a band of %dx%d with %d channels does not continue a %dx%d "
                            "image of %d channels at row %d",
                            path, rows->width, rows->height, rows->channels, stream->layout.width,
                            stream->layout.height, stream->layout.channels, stream->next_row);
    std::string failure;
    try {
        rt_image band = stream->layout;
        band.height = rows->height;
        band.pixels = rows->pixels;
        OIIO::ImageBuf converted = pixels_for_kind(stream->kind, &band, stream->exposure);
        /* An EXR's rows are numbered within its data window, which starts at its place. */
        int first = stream->next_row + (stream->kind == file_kind::exr && stream->layout.full_width > 0
                                            ? stream->layout.y : 0);
        if (!stream->output->write_scanlines(first, first + rows->height, 0, OIIO::TypeDesc::FLOAT,
                                             converted.localpixels()))
            failure = one_line(stream->output->geterror());
    } catch (const std::bad_alloc &) {
        failure = "out of memory";
    } catch (const std::exception &e) {
        failure = one_line(e.what());
    } catch (...) {
        failure = "unexpected C++ exception";
    }
    if (!failure.empty())
        return write_failed(error, path, failure);
    stream->next_row += rows->height;
    return RT_OK;
}

rt_status image_stream_close(image_stream *stream, rt_error *error)
{
    std::string path = stream->destination;
    std::string failure;
    if (stream->next_row != stream->layout.height)
        failure = "only " + std::to_string(stream->next_row) + " of its " + std::to_string(stream->layout.height)
                  + " rows were written";
    if (failure.empty() && !stream->output->close())
        failure = one_line(stream->output->geterror());
    if (failure.empty()) {
        int fd = ::open(stream->temporary.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd >= 0) {
            if (fsync(fd) != 0 && errno != EINVAL)
                failure = strerror(errno);
            ::close(fd);
        }
    }
    if (failure.empty() && rename(stream->temporary.c_str(), path.c_str()) != 0)
        failure = std::string("cannot rename the temporary file over it: ") + strerror(errno);
    if (!failure.empty()) {
        stream->output.reset();
        abandon_stream(stream);
        return write_failed(error, path.c_str(), failure);
    }
    std::string directory = stream->directory;
    stream->temporary.clear();
    stream->output.reset();
    delete stream;
    sync_directory(directory);
    return RT_OK;
}

void image_stream_abandon(image_stream *stream)
{
    if (stream != nullptr)
        abandon_stream(stream);
}


image_write_options image_write_options_defaults(void)
{
    return image_write_options{};
}

image_format image_format_of(const char *path)
{
    file_kind kind = file_kind::unknown;
    try {
        kind = kind_of_extension(extension_of(path != nullptr ? path : ""));
    } catch (...) {
        /* Only an allocation can fail here; a name that cannot be examined has no format. */
    }
    switch (kind) {
    case file_kind::exr: return IMAGE_FORMAT_EXR;
    case file_kind::hdr: return IMAGE_FORMAT_HDR;
    case file_kind::eight_bit: return IMAGE_FORMAT_EIGHT_BIT;
    case file_kind::unknown: break;
    }
    return IMAGE_FORMAT_UNKNOWN;
}

rt_status image_create(rt_image *image, int width, int height, int channels, rt_error *error)
{
    memset(image, 0, sizeof *image);
    if (width <= 0 || height <= 0 || channels <= 0 || channels > IMAGE_MAX_CHANNELS)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "IMAGE: cannot create a %dx%d image with %d channels", width, height,
                            channels);
    size_t count = (size_t)width * (size_t)height;
    if (count > SIZE_MAX / sizeof(float) / (size_t)channels)
        return rt_error_set(error, RT_ERROR_RUNTIME, "IMAGE: a %dx%d image is too large",
                            width, height);
    image->pixels = (float *)calloc(count * (size_t)channels, sizeof(float));
    if (image->pixels == nullptr)
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "IMAGE: out of memory for a %dx%d image with %d channels", width,
                            height, channels);
    image->width = width;
    image->height = height;
    image->channels = channels;
    return RT_OK;
}

rt_status image_append_channels(const rt_image *a, const rt_image *b, rt_image *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    if (a->width != b->width || a->height != b->height)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: cannot join a %dx%d and a %dx%d image", a->width,
                            a->height, b->width, b->height);
    rt_status status = image_create(out, a->width, a->height, a->channels + b->channels, error);
    if (status != RT_OK)
        return status;
    try {
        OIIO::ImageBuf joined = OIIO::ImageBufAlgo::channel_append(wrap(a), wrap(b));
        check(joined.get_pixels(joined.roi(), OIIO::TypeDesc::FLOAT, out->pixels), joined);
        for (int c = 0; c < out->channels; c++)
            snprintf(out->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", joined.spec().channelnames[c].c_str());
    } catch (const std::exception &e) {
        image_free(out);
        return rt_error_set(error, RT_ERROR_RUNTIME, "IMAGE: cannot join two images: %s", one_line(e.what()).c_str());
    }
    out->x = a->x;
    out->y = a->y;
    out->full_width = a->full_width;
    out->full_height = a->full_height;
    return RT_OK;
}

rt_status image_color_map(const rt_image *image, int channel, const char *map, rt_image *out, rt_error *error)
{
    std::memset(out, 0, sizeof *out);
    if (channel < 0 || channel >= image->channels)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: no channel %d to map in an image of %d channels", channel,
                            image->channels);
    rt_status status = image_create(out, image->width, image->height, 3, error);
    if (status != RT_OK)
        return status;
    try {
        OIIO::ImageBuf mapped = OIIO::ImageBufAlgo::color_map(wrap(image), channel, map);
        check(mapped.initialized(), mapped);
        check(mapped.get_pixels(mapped.roi(), OIIO::TypeDesc::FLOAT, out->pixels), mapped);
    } catch (const std::exception &e) {
        image_free(out);
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: cannot apply the colour map '%s': %s", map,
                            one_line(e.what()).c_str());
    }
    return RT_OK;
}

int image_channel_index(const rt_image *image, const char *name)
{
    for (int c = 0; c < image->channels; c++)
        if (std::strcmp(image->channel_names[c], name) == 0)
            return c;
    return -1;
}

void image_free(rt_image *image)
{
    if (image == nullptr)
        return;
    free(image->pixels);
    memset(image, 0, sizeof *image);
}

rt_status image_write(const char *path, const rt_image *image, const image_write_options *options,
                      rt_error *error)
{
    if (path == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: no path to write the image to");
    try {
        return image_write_impl(path, image, options, error);
    } catch (const std::exception &e) {
        return write_failed(error, path, one_line(e.what()));
    } catch (...) {
        return write_failed(error, path, "unexpected C++ exception");
    }
}

rt_status image_read(const char *path, rt_image *out, rt_error *error)
{
    return image_read_guarded(path, 0, false, out, error);
}

rt_status image_read_linear(const char *path, int max_side, rt_image *out, rt_error *error)
{
    return image_read_guarded(path, max_side, true, out, error);
}

rt_status image_read_memory(const void *bytes, size_t size, const char *name, int max_side, bool linear,
                            rt_image *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    if (name == nullptr)
        name = "<memory>";
    memory_file memory = {bytes, size};
    try {
        return image_read_impl(name, max_side, linear, out, error, &memory);
    } catch (const std::bad_alloc &) {
        image_free(out);
        return rt_error_set(error, RT_ERROR_RUNTIME, "IMAGE: cannot read '%s': out of memory", name);
    } catch (const std::exception &e) {
        image_free(out);
        return read_failed(error, name, one_line(e.what()));
    } catch (...) {
        image_free(out);
        return read_failed(error, name, "unexpected C++ exception");
    }
}

float image_srgb_decode(float value)
{
    return srgb_decode(value);
}

rt_status image_read_attribute(const char *path, const char *name, char *value, int value_size,
                               rt_error *error)
{
    if (path == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: no path to read an attribute from");
    try {
        return image_read_attribute_impl(path, name, value, value_size, error);
    } catch (const std::exception &e) {
        return read_failed(error, path, one_line(e.what()));
    } catch (...) {
        return read_failed(error, path, "unexpected C++ exception");
    }
}

rt_status image_read_attributes(const char *path, const char *prefix, image_attribute_set *out, rt_error *error)
{
    image_attribute_set_free(out);
    if (path == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "IMAGE: no path to read attributes from");
    try {
        return read_attributes_impl(path, prefix ? prefix : "", out, error);
    } catch (const std::bad_alloc &) {
        image_attribute_set_free(out);
        return rt_error_set(error, RT_ERROR_RUNTIME, "IMAGE: cannot read '%s': out of memory", path);
    } catch (const std::exception &e) {
        image_attribute_set_free(out);
        return read_failed(error, path, one_line(e.what()));
    } catch (...) {
        image_attribute_set_free(out);
        return read_failed(error, path, "unexpected C++ exception");
    }
}

rt_status image_attribute_set_put(image_attribute_set *set, const image_attribute *attribute, rt_error *error)
{
    image_attribute copy = *attribute;
    copy.name = strdup(attribute->name ? attribute->name : "");
    copy.string_value = attribute->string_value ? strdup(attribute->string_value) : nullptr;
    image_attribute *grown = nullptr;
    const image_attribute *existing = image_attribute_set_find(set, copy.name ? copy.name : "");
    if (existing == nullptr && copy.name != nullptr)
        grown = (image_attribute *)realloc(set->attributes, ((size_t)set->count + 1) * sizeof *grown);
    if (copy.name == nullptr || (attribute->string_value && copy.string_value == nullptr)
        || (existing == nullptr && grown == nullptr)) {
        free((void *)copy.name);
        free((void *)copy.string_value);
        return rt_error_set(error, RT_ERROR_RUNTIME, "IMAGE: out of memory for metadata '%s'",
                            attribute->name ? attribute->name : "");
    }
    if (existing != nullptr) {
        image_attribute *slot = set->attributes + (existing - set->attributes);
        free((void *)slot->name);
        free((void *)slot->string_value);
        *slot = copy;
        return RT_OK;
    }
    set->attributes = grown;
    set->attributes[set->count++] = copy;
    return RT_OK;
}

const image_attribute *image_attribute_set_find(const image_attribute_set *set, const char *name)
{
    for (int i = 0; i < set->count; i++)
        if (strcmp(set->attributes[i].name, name) == 0)
            return &set->attributes[i];
    return nullptr;
}

void image_attribute_set_remove(image_attribute_set *set, const char *name)
{
    const image_attribute *found = image_attribute_set_find(set, name);
    if (found == nullptr)
        return;
    int index = (int)(found - set->attributes);
    free((void *)set->attributes[index].name);
    free((void *)set->attributes[index].string_value);
    memmove(set->attributes + index, set->attributes + index + 1,
            (size_t)(set->count - index - 1) * sizeof *set->attributes);
    set->count--;
}

void image_attribute_set_free(image_attribute_set *set)
{
    for (int i = 0; i < set->count; i++) {
        free((void *)set->attributes[i].name);
        free((void *)set->attributes[i].string_value);
    }
    free(set->attributes);
    set->attributes = nullptr;
    set->count = 0;
}

}  // extern "C"
