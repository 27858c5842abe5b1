#pragma once
// A small line-plot writer on OpenCV drawing, for the tools' diagnostic PNGs: a figure of
// stacked panels sharing nothing but the width, each with axes, "nice" ticks, labels, any
// number of x/y series and a legend. NaN y values break a line (gaps in the data).
#include <expected>
#include <string>
#include <vector>

namespace cv { class Mat; }

namespace epichead::tools::plot {

struct Series {
  std::string label;
  std::vector<double> x, y;  // same length; x ascending is not required
  // Drawing style: a line through the points, or a dot at each point (for sparse events).
  enum class Style { Line, Dots } style = Style::Line;
};

struct Panel {
  std::string title;
  std::string x_label, y_label;
  std::vector<Series> series;
};

struct Figure {
  std::string title;
  std::vector<Panel> panels;
  int width_px = 1200;
  int panel_height_px = 320;
};

// Renders the figure into an 8-bit BGR image (white background).
cv::Mat render(const Figure& figure);

// Renders and writes a PNG; the error names the path.
std::expected<void, std::string> write_png(const Figure& figure, const std::string& path);

// Tick positions between lo and hi with a 1-2-5 step, about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

}  // namespace epichead::tools::plot
