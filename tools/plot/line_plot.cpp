#include "plot/line_plot.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace epichead::tools::plot {
namespace {

const cv::Scalar kPalette[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},
                               {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127}};
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kLeft = 80, kRight = 20, kTop = 30, kBottom = 45, kTitle = 36;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  // Empty or zero-width ranges get a visible width around their value.
  void settle() {
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
      const double pad = std::max(1.0, std::abs(hi)) * 0.5;
      lo -= pad;
      hi += pad;
    }
  }
};

std::string tick_label(double v, double step) {
  char buf[32];
  if (std::abs(v) < step * 1e-6) v = 0;
  const int decimals = step >= 1 ? 0 : std::min(6, static_cast<int>(std::ceil(-std::log10(step))));
  if (std::abs(v) >= 1e6 || (v != 0 && std::abs(v) < 1e-4))
    std::snprintf(buf, sizeof buf, "%.2g", v);
  else
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

void draw_panel(cv::Mat& img, const Panel& panel, cv::Rect area) {
  const cv::Rect plot(area.x + kLeft, area.y + kTop, area.width - kLeft - kRight, area.height - kTop - kBottom);
  Range xr, yr;
  for (const auto& s : panel.series)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) xr.add(s.x[i]), yr.add(s.y[i]);
  xr.settle();
  yr.settle();
  const double ypad = 0.05 * (yr.hi - yr.lo);
  yr.lo -= ypad;
  yr.hi += ypad;
  const auto px = [&](double x) { return plot.x + (x - xr.lo) / (xr.hi - xr.lo) * plot.width; };
  const auto py = [&](double y) { return plot.y + plot.height - (y - yr.lo) / (yr.hi - yr.lo) * plot.height; };

  cv::putText(img, panel.title, {area.x + kLeft, area.y + 20}, kFont, 0.55, {0, 0, 0}, 1, cv::LINE_AA);
  const auto xt = nice_ticks(xr.lo, xr.hi);
  const auto yt = nice_ticks(yr.lo, yr.hi);
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1, ystep = yt.size() > 1 ? yt[1] - yt[0] : 1;
  for (double t : xt) {
    const int x = static_cast<int>(std::lround(px(t)));
    cv::line(img, {x, plot.y}, {x, plot.y + plot.height}, {230, 230, 230}, 1);
    const std::string label = tick_label(t, xstep);
    int base = 0;
    const cv::Size size = cv::getTextSize(label, kFont, 0.4, 1, &base);
    cv::putText(img, label, {x - size.width / 2, plot.y + plot.height + 16}, kFont, 0.4, {60, 60, 60}, 1, cv::LINE_AA);
  }
  for (double t : yt) {
    const int y = static_cast<int>(std::lround(py(t)));
    cv::line(img, {plot.x, y}, {plot.x + plot.width, y}, {230, 230, 230}, 1);
    const std::string label = tick_label(t, ystep);
    int base = 0;
    const cv::Size size = cv::getTextSize(label, kFont, 0.4, 1, &base);
    cv::putText(img, label, {plot.x - size.width - 6, y + 4}, kFont, 0.4, {60, 60, 60}, 1, cv::LINE_AA);
  }
  cv::rectangle(img, plot, {0, 0, 0}, 1);
  cv::putText(img, panel.x_label, {plot.x + plot.width / 2 - 40, plot.y + plot.height + 36}, kFont, 0.45, {0, 0, 0}, 1,
              cv::LINE_AA);
  cv::putText(img, panel.y_label, {area.x + 4, plot.y - 8}, kFont, 0.45, {0, 0, 0}, 1, cv::LINE_AA);

  cv::Mat clip = img(plot);
  for (std::size_t k = 0; k < panel.series.size(); ++k) {
    const Series& s = panel.series[k];
    const cv::Scalar colour = kPalette[k % std::size(kPalette)];
    std::vector<cv::Point> run;
    const auto flush = [&] {
      if (run.size() >= 2) cv::polylines(clip, run, false, colour, 1, cv::LINE_AA);
      run.clear();
    };
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        flush();
        continue;
      }
      const cv::Point p(static_cast<int>(std::lround(px(s.x[i]))) - plot.x,
                        static_cast<int>(std::lround(py(s.y[i]))) - plot.y);
      if (s.style == Series::Style::Dots)
        cv::circle(clip, p, 2, colour, cv::FILLED, cv::LINE_AA);
      else
        run.push_back(p);
    }
    flush();
  }
  // Legend, top right inside the plot.
  int y = plot.y + 16;
  for (std::size_t k = 0; k < panel.series.size(); ++k) {
    const std::string& label = panel.series[k].label;
    if (label.empty()) continue;
    int base = 0;
    const cv::Size size = cv::getTextSize(label, kFont, 0.42, 1, &base);
    const int x = plot.x + plot.width - size.width - 36;
    cv::rectangle(img, {x - 4, y - 12, size.width + 36, 17}, {255, 255, 255}, cv::FILLED);
    cv::line(img, {x, y - 4}, {x + 22, y - 4}, kPalette[k % std::size(kPalette)], 2);
    cv::putText(img, label, {x + 28, y}, kFont, 0.42, {0, 0, 0}, 1, cv::LINE_AA);
    y += 18;
  }
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
  const double raw = (hi - lo) / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  for (double t = std::ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) ticks.push_back(t);
  return ticks;
}

cv::Mat render(const Figure& figure) {
  const int panels = std::max<int>(1, static_cast<int>(figure.panels.size()));
  cv::Mat img(kTitle + panels * figure.panel_height_px, figure.width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(img, figure.title, {10, 24}, kFont, 0.65, {0, 0, 0}, 1, cv::LINE_AA);
  for (int i = 0; i < static_cast<int>(figure.panels.size()); ++i)
    draw_panel(img, figure.panels[static_cast<std::size_t>(i)],
               cv::Rect(0, kTitle + i * figure.panel_height_px, figure.width_px, figure.panel_height_px));
  return img;
}

std::expected<void, std::string> write_png(const Figure& figure, const std::string& path) {
  try {
    if (!cv::imwrite(path, render(figure))) return std::unexpected(path + ": cannot write PNG");
  } catch (const cv::Exception& e) {
    return std::unexpected(path + ": cannot write PNG (" + e.what() + ")");
  }
  return {};
}

}  // namespace epichead::tools::plot
