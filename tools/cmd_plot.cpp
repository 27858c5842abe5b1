// `epichead plot CSV --x COL --y COL[,COL...] [--group COL[,COL...]] --out PNG [--title T]`: a
// line plot of CSV columns, one series per y column and per distinct value of the group columns
// (for the result scripts: no plotting dependency beyond what the tools already use).
#include <CLI/CLI.hpp>

#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "command.h"
#include "plot/line_plot.h"

namespace epichead::tools {
namespace {

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, sep)) {
    if (!part.empty() && part.back() == '\r') part.pop_back();
    out.push_back(part);
  }
  if (!text.empty() && text.back() == sep) out.emplace_back();
  return out;
}

struct PlotArgs {
  std::string csv, x, y, group, out, title;
};

int run_plot(const PlotArgs& a) {
  const char* cmd = "plot";
  std::ifstream in(a.csv);
  if (!in) return fail(cmd, a.csv + ": cannot open");
  std::string line;
  if (!std::getline(in, line)) return fail(cmd, a.csv + ": empty file (expected a header row)");
  const std::vector<std::string> header = split(line, ',');
  auto column = [&](const std::string& name) -> int {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  };
  const int xi = column(a.x);
  if (xi < 0) return fail(cmd, a.csv + ": no column '" + a.x + "'");
  std::vector<int> ys, groups;
  for (const std::string& name : split(a.y, ',')) {
    const int c = column(name);
    if (c < 0) return fail(cmd, a.csv + ": no column '" + name + "'");
    ys.push_back(c);
  }
  if (!a.group.empty())
    for (const std::string& name : split(a.group, ',')) {
      const int c = column(name);
      if (c < 0) return fail(cmd, a.csv + ": no column '" + name + "'");
      groups.push_back(c);
    }

  std::map<std::string, plot::Series> series;  // by label, in label order
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> f = split(line, ',');
    if (f.size() != header.size())
      return fail(cmd, a.csv + ":" + std::to_string(number) + ": " + std::to_string(f.size()) + " fields, header has " +
                           std::to_string(header.size()));
    std::string key;
    for (int g : groups) key += (key.empty() ? "" : " ") + header[static_cast<std::size_t>(g)] + "=" + f[static_cast<std::size_t>(g)];
    double x = 0;
    try {
      x = std::stod(f[static_cast<std::size_t>(xi)]);
    } catch (const std::exception&) {
      return fail(cmd, a.csv + ":" + std::to_string(number) + ": '" + f[static_cast<std::size_t>(xi)] + "' is not a number");
    }
    for (int y : ys) {
      const std::string label = (ys.size() > 1 || key.empty() ? header[static_cast<std::size_t>(y)] + (key.empty() ? "" : " ") : "") + key;
      double v = std::numeric_limits<double>::quiet_NaN();  // an empty or non-numeric cell is a gap
      try {
        v = std::stod(f[static_cast<std::size_t>(y)]);
      } catch (const std::exception&) {
      }
      plot::Series& s = series[label];
      s.label = label;
      s.x.push_back(x);
      s.y.push_back(v);
    }
  }
  plot::Figure fig;
  fig.title = a.title.empty() ? a.csv : a.title;
  plot::Panel panel;
  panel.x_label = a.x;
  panel.y_label = a.y;
  for (auto& [label, s] : series) panel.series.push_back(std::move(s));
  if (panel.series.empty()) return fail(cmd, a.csv + ": no data rows");
  fig.panels.push_back(std::move(panel));
  if (auto ok = plot::write_png(fig, a.out); !ok) return fail(cmd, ok.error());
  return 0;
}

const CommandRegistration registration{
    "plot", "Plot CSV columns as lines into a PNG (one series per y column and group)", [](CLI::App& app) {
      auto a = std::make_shared<PlotArgs>();
      app.add_option("CSV", a->csv, "CSV file with a header row")->required();
      app.add_option("--x", a->x, "Column for the x axis")->required();
      app.add_option("--y", a->y, "Column(s) for the y axis, comma-separated")->required();
      app.add_option("--group", a->group, "Column(s) whose values split the rows into series");
      app.add_option("--title", a->title, "Figure title (default: the file name)");
      app.add_option("--out", a->out, "PNG to write")->required();
      return [a]() { return run_plot(*a); };
    }};

}  // namespace
}  // namespace epichead::tools
