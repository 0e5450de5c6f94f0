// plot.cpp: draws `make bench`'s chart of time per sample against triangle count (log x
// axis) as a PNG with OpenImageIO's drawing functions (ImageBufAlgo::render_line,
// render_box, render_text). OpenImageIO is already a dependency of rtspheres; gnuplot
// is not, and adding a plotting package to a renderer's dependencies for one chart is
// not worth it.
//
// Text needs a TrueType font. OpenImageIO finds DejaVu Sans under /usr/share/fonts,
// which a fresh Debian 12 gets with rtspheres' packages (fontconfig-config depends on
// fonts-dejavu-core). When no font works, the chart is still drawn (axes, ticks,
// points, the target line) and every label goes to OUT-without-extension.txt instead,
// with a warning on stderr.
//
// usage: plot DATA OUT.png [--font NAME]
//   DATA: one point a line, "TRIANGLES SECONDS_PER_SAMPLE NAME" (NAME without spaces);
//   '#' lines are comments. The first point (fewest triangles) is the base of the
//   target line, 2.5 times its time per sample.
// Exit status: 0 written, 1 could not write, 2 bad input.

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace algo = OIIO::ImageBufAlgo;

struct point {
    double triangles;
    double seconds_per_sample;
    std::string name;
};

const int WIDTH = 860, HEIGHT = 520;
const int LEFT = 100, RIGHT = 40, TOP = 80, BOTTOM = 80;   // plot area margins
const float BLACK[3] = {0, 0, 0}, GREY[3] = {0.82f, 0.82f, 0.82f}, BLUE[3] = {0.1f, 0.3f, 0.8f},
            RED[3] = {0.8f, 0.15f, 0.1f};
const double GROWTH_TARGET = 2.5;   // issue #6: time per sample from 1k to 1M triangles

// Reads the data file; returns the points sorted by triangle count, or an empty vector
// (with a message) when the file is unreadable or a line is malformed.
std::vector<point> read_points(const std::string &path)
{
    std::vector<point> points;
    std::ifstream file(path);
    if (!file) {
        std::fprintf(stderr, "plot: cannot read %s\n", path.c_str());
        return points;
    }
    std::string line;
    while (std::getline(file, line)) {
        if (line.empty() || line[0] == '#')
            continue;
        std::istringstream fields(line);
        point p;
        if (!(fields >> p.triangles >> p.seconds_per_sample >> p.name) || !(p.triangles > 0)
            || !(p.seconds_per_sample > 0)) {
            std::fprintf(stderr, "plot: %s: bad line \"%s\"\n", path.c_str(), line.c_str());
            return {};
        }
        points.push_back(p);
    }
    std::sort(points.begin(), points.end(),
              [](const point &a, const point &b) { return a.triangles < b.triangles; });
    return points;
}

// Returns the smallest "nice" number (1, 2 or 5 times a power of ten) at least value.
double nice_ceiling(double value)
{
    double decade = std::pow(10.0, std::floor(std::log10(value)));
    for (double step : {1.0, 2.0, 5.0, 10.0})
        if (step * decade >= value * (1 - 1e-9))
            return step * decade;
    return 10 * decade;
}

// Returns a triangle count in words a reader takes in at a glance: 1k, 100k, 1M.
std::string count_label(double count)
{
    char text[32];
    if (count >= 1e6)
        std::snprintf(text, sizeof text, "%.3gM", count / 1e6);
    else if (count >= 1e3)
        std::snprintf(text, sizeof text, "%.3gk", count / 1e3);
    else
        std::snprintf(text, sizeof text, "%g", count);
    return text;
}

// Draws text, or keeps it for the sidecar file when no font works; fonts_work tells
// which, labels collects the text with its place.
struct text_painter {
    OIIO::ImageBuf &image;
    std::string font;
    bool fonts_work;
    std::vector<std::string> labels;

    // Draws text at (x, y) aligned as asked, or files it in labels when fonts fail.
    void draw(int x, int y, const std::string &text, int size, algo::TextAlignX align_x,
              algo::TextAlignY align_y, const float *colour = BLACK)
    {
        if (fonts_work
            && algo::render_text(image, x, y, text, size, font, OIIO::cspan<float>(colour, 3), align_x, align_y))
            return;
        fonts_work = false;
        labels.push_back(text);
    }
};

// Returns the first font OpenImageIO can use from the candidates (the one asked for
// first), or "" with found false.
std::string find_font(const std::string &asked, bool &found)
{
    std::vector<std::string> candidates;
    if (!asked.empty())
        candidates.push_back(asked);
    else
        candidates = {"DejaVuSans", "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", ""};
    for (const std::string &font : candidates) {
        if (algo::text_size("0", 14, font).defined()) {
            found = true;
            return font;
        }
    }
    found = false;
    return "";
}

// Draws a dashed horizontal line from x0 to x1 at y.
void dashed_line(OIIO::ImageBuf &image, int x0, int x1, int y, const float *colour)
{
    for (int x = x0; x < x1; x += 12)
        algo::render_line(image, x, y, std::min(x + 6, x1), y, OIIO::cspan<float>(colour, 3));
}

// Draws the whole chart into image; returns the labels that could not be drawn.
std::vector<std::string> draw_chart(OIIO::ImageBuf &image, const std::vector<point> &points,
                                    const std::string &font, bool font_found)
{
    text_painter text{image, font, font_found, {}};
    const int x0 = LEFT, x1 = WIDTH - RIGHT, y0 = HEIGHT - BOTTOM, y1 = TOP;   // y0: bottom

    // Axes ranges: whole decades in x, 0 to a nice ceiling in y (microseconds).
    double low_decade = std::floor(std::log10(points.front().triangles));
    double high_decade = std::ceil(std::log10(points.back().triangles));
    if (high_decade <= low_decade)
        high_decade = low_decade + 1;
    double base_us = points.front().seconds_per_sample * 1e6;
    double top_us = base_us * GROWTH_TARGET;
    for (const point &p : points)
        top_us = std::max(top_us, p.seconds_per_sample * 1e6);
    top_us = nice_ceiling(top_us * 1.1);
    auto x_of = [&](double triangles) {
        return x0 + (int)std::lround((std::log10(triangles) - low_decade) / (high_decade - low_decade) * (x1 - x0));
    };
    auto y_of = [&](double us) { return y0 - (int)std::lround(us / top_us * (y0 - y1)); };

    // Grid and ticks: decades with labels, 2..9 times a decade as short ticks.
    for (double decade = low_decade; decade <= high_decade; decade += 1) {
        int x = x_of(std::pow(10.0, decade));
        algo::render_line(image, x, y0, x, y1, OIIO::cspan<float>(GREY, 3));
        algo::render_line(image, x, y0, x, y0 + 8, OIIO::cspan<float>(BLACK, 3));
        text.draw(x, y0 + 12, count_label(std::pow(10.0, decade)), 16, algo::TextAlignX::Center,
                  algo::TextAlignY::Top);
        for (int multiple = 2; multiple <= 9 && decade < high_decade; multiple++) {
            int minor = x_of(multiple * std::pow(10.0, decade));
            algo::render_line(image, minor, y0, minor, y0 + 4, OIIO::cspan<float>(BLACK, 3));
        }
    }
    const int y_steps = 5;
    for (int step = 0; step <= y_steps; step++) {
        double us = top_us * step / y_steps;
        int y = y_of(us);
        if (step > 0)
            algo::render_line(image, x0, y, x1, y, OIIO::cspan<float>(GREY, 3));
        algo::render_line(image, x0 - 8, y, x0, y, OIIO::cspan<float>(BLACK, 3));
        char label[32];
        std::snprintf(label, sizeof label, "%g", us);
        text.draw(x0 - 12, y, label, 16, algo::TextAlignX::Right, algo::TextAlignY::Center);
    }
    algo::render_box(image, x0, y1, x1, y0, OIIO::cspan<float>(BLACK, 3));

    // The target: time per sample at most 2.5 times the smallest mesh's.
    int target_y = y_of(base_us * GROWTH_TARGET);
    dashed_line(image, x0 + 1, x1 - 1, target_y, RED);
    char target_label[96];
    std::snprintf(target_label, sizeof target_label, "target: %.2g x the %s mesh (%.3g us)", GROWTH_TARGET,
                  count_label(points.front().triangles).c_str(), base_us * GROWTH_TARGET);
    text.draw(x1 - 6, target_y - 6, target_label, 14, algo::TextAlignX::Right, algo::TextAlignY::Bottom, RED);

    // The measurements: a polyline and a labelled box per point.
    for (size_t i = 0; i < points.size(); i++) {
        int x = x_of(points[i].triangles), y = y_of(points[i].seconds_per_sample * 1e6);
        if (i > 0)
            algo::render_line(image, x_of(points[i - 1].triangles), y_of(points[i - 1].seconds_per_sample * 1e6), x, y,
                              OIIO::cspan<float>(BLUE, 3), true);
        algo::render_box(image, x - 4, y - 4, x + 4, y + 4, OIIO::cspan<float>(BLUE, 3), true);
        char label[96];
        std::snprintf(label, sizeof label, "%s: %.3g us", count_label(points[i].triangles).c_str(),
                      points[i].seconds_per_sample * 1e6);
        text.draw(x, y + 10, label, 14, i + 1 == points.size() ? algo::TextAlignX::Right : algo::TextAlignX::Left,
                  algo::TextAlignY::Top, BLUE);
    }

    text.draw(WIDTH / 2, 12, "rtspheres: time per sample against triangle count", 20, algo::TextAlignX::Center,
              algo::TextAlignY::Top);
    text.draw((x0 + x1) / 2, HEIGHT - 10, "triangles (icosphere meshes, log scale)", 16, algo::TextAlignX::Center,
              algo::TextAlignY::Bottom);
    text.draw(14, TOP - 12, "time per sample once set up: the passes after the first (microseconds)", 16, algo::TextAlignX::Left,
              algo::TextAlignY::Bottom);
    return text.fonts_work ? std::vector<std::string>{} : text.labels;
}

} // namespace

// Reads the points, draws the chart and writes the PNG (and the sidecar of labels when
// no font worked); returns the exit status described at the top.
int main(int argc, char **argv)
{
    if (argc != 3 && !(argc == 5 && std::string(argv[3]) == "--font")) {
        std::fprintf(stderr, "usage: plot DATA OUT.png [--font NAME]\n");
        return 2;
    }
    std::vector<point> points = read_points(argv[1]);
    if (points.empty()) {
        std::fprintf(stderr, "plot: no points in %s\n", argv[1]);
        return 2;
    }
    bool font_found = false;
    std::string font = find_font(argc == 5 ? argv[4] : "", font_found);

    OIIO::ImageBuf image(OIIO::ImageSpec(WIDTH, HEIGHT, 3, OIIO::TypeDesc::FLOAT));
    const float white[3] = {1, 1, 1};
    algo::fill(image, OIIO::cspan<float>(white, 3));
    std::vector<std::string> lost_labels = draw_chart(image, points, font, font_found);

    std::string output = argv[2];
    image.set_write_format(OIIO::TypeDesc::UINT8);
    if (!image.write(output)) {
        std::fprintf(stderr, "plot: cannot write %s: %s\n", output.c_str(), image.geterror().c_str());
        return 1;
    }
    if (!lost_labels.empty()) {
        std::string sidecar = output.substr(0, output.rfind('.')) + ".txt";
        std::ofstream labels(sidecar);
        labels << "# labels of " << output << " (no usable font for OpenImageIO's render_text)\n";
        for (const std::string &label : lost_labels)
            labels << label << "\n";
        std::fprintf(stderr, "plot: no usable font; drew %s without text, labels in %s\n", output.c_str(),
                     sidecar.c_str());
        if (!labels)
            return 1;
    }
    return 0;
}
