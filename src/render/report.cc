#include "render/report.h"

#include <glib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>

#include "common/error.h"
#include "common/file_io.h"
#include "common/json_fields.h"

namespace m2d {
namespace {

constexpr const char* kKnownEvalColumns[] = {"clip",   "view",   "succ",
                                             "e2d_px", "e3d_mm", "jitter"};

std::string EscapeHtml(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&#39;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::string Base64(const std::string& bytes) {
  std::unique_ptr<gchar, decltype(&g_free)> encoded(
      g_base64_encode(reinterpret_cast<const guchar*>(bytes.data()),
                      bytes.size()),
      &g_free);
  return encoded.get();
}

// MIME type of a media file from its extension; InputError otherwise.
std::string MediaType(const std::string& path, bool video) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 ::tolower);
  static const std::map<std::string, std::string> kImages = {
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".gif", "image/gif"},
      {".svg", "image/svg+xml"}};
  static const std::map<std::string, std::string> kVideos = {
      {".mp4", "video/mp4"}, {".webm", "video/webm"}};
  const auto& types = video ? kVideos : kImages;
  auto it = types.find(extension);
  if (it == types.end()) {
    throw InputError(
        path, std::string("unsupported ") + (video ? "video" : "image") +
                  " type (use " +
                  (video ? ".mp4 or .webm" : ".png, .jpg, .gif or .svg") + ")");
  }
  return it->second;
}

std::string DataUri(const std::string& path, bool video) {
  const std::string type = MediaType(path, video);
  return "data:" + type + ";base64," + Base64(ReadFileText(path));
}

std::string FormatCell(const JsonCursor& cell) {
  const nlohmann::json& value = cell.value();
  if (value.is_null()) return "\u2014";
  if (value.is_boolean()) return value.get<bool>() ? "yes" : "no";
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_integer()) return std::to_string(value.get<long>());
  if (value.is_number()) {
    const double number = value.get<double>();
    if (!std::isfinite(number)) return "\u2014";
    char text[32];
    std::snprintf(text, sizeof(text), "%.4g", number);
    return text;
  }
  cell.Fail("expected a string, number, true/false or null");
}

std::string Timestamp() {
  std::time_t now = std::time(nullptr);
  char text[64];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S %Z",
                std::localtime(&now));
  return text;
}

constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 2em auto; max-width: 1500px;
       padding: 0 1em; color: #222; }
h1 { margin-bottom: 0.2em; }
.meta { color: #666; margin-top: 0; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #ccc; padding: 0.3em 0.8em; text-align: right; }
th { background: #f0f0f0; }
td.text { text-align: left; }
figure { margin: 1em 0; }
figure img, figure video { max-width: 100%; border: 1px solid #ddd; }
figcaption { color: #555; font-size: 0.9em; }
#media-check { color: #666; font-size: 0.9em; }
)";

// Counts decoded images and videos into #media-check, so a headless
// browser (or a reader) can tell the embedded media work.
constexpr const char* kMediaCheckScript = R"(
(function () {
  var status = document.getElementById('media-check');
  var images = Array.prototype.slice.call(document.images);
  var videos = Array.prototype.slice.call(document.querySelectorAll('video'));
  var videosReady = 0, videosFailed = 0;
  function update() {
    var imagesReady = images.filter(function (image) {
      return image.complete && image.naturalWidth > 0;
    }).length;
    status.textContent = 'media check: ' + imagesReady + '/' + images.length +
        ' images, ' + videosReady + '/' + videos.length + ' videos decoded' +
        (videosFailed ? ', ' + videosFailed + ' videos failed' : '');
  }
  videos.forEach(function (video) {
    if (video.error) { videosFailed++; return; }
    if (video.readyState >= 1) { videosReady++; return; }
    video.addEventListener('loadedmetadata', function () {
      videosReady++; update();
    });
    video.addEventListener('error', function () {
      videosFailed++; update();
    });
  });
  window.addEventListener('load', update);
  update();
})();
)";

void AppendEvalTable(const EvalTable& table, std::string* html) {
  if (table.rows.empty()) {
    *html += "<p>The evaluation file has no rows.</p>\n";
    return;
  }
  *html += "<table>\n<tr>";
  for (const std::string& column : table.columns) {
    *html += "<th>" + EscapeHtml(EvalColumnHeading(column)) + "</th>";
  }
  *html += "</tr>\n";
  for (const std::vector<std::string>& row : table.rows) {
    *html += "<tr>";
    for (size_t c = 0; c < row.size(); ++c) {
      const bool text =
          table.columns[c] == "clip" || table.columns[c] == "view";
      *html += (text ? "<td class=\"text\">" : "<td>") + EscapeHtml(row[c]) +
               "</td>";
    }
    *html += "</tr>\n";
  }
  *html += "</table>\n";
}

}  // namespace

EvalTable ReadEvalTable(const std::string& json_path) {
  const nlohmann::json json = ReadJsonFile(json_path);
  const JsonCursor rows = JsonCursor(json, json_path).Field("rows");
  const size_t num_rows = rows.ArraySize();
  EvalTable table;
  // Columns: the known keys present anywhere, then the others.
  std::vector<std::string> others;
  for (size_t r = 0; r < num_rows; ++r) {
    const JsonCursor row = rows.At(r);
    if (!row.value().is_object()) row.Fail("expected an object");
    for (const auto& item : row.value().items()) {
      const std::string& key = item.key();
      // Nested detail (eval's per-rollout list) is not a table cell.
      if (item.value().is_structured()) continue;
      const bool known =
          std::find(std::begin(kKnownEvalColumns), std::end(kKnownEvalColumns),
                    key) != std::end(kKnownEvalColumns);
      if (!known &&
          std::find(others.begin(), others.end(), key) == others.end()) {
        others.push_back(key);
      }
    }
  }
  for (const char* key : kKnownEvalColumns) {
    for (size_t r = 0; r < num_rows; ++r) {
      if (rows.At(r).Has(key)) {
        table.columns.push_back(key);
        break;
      }
    }
  }
  table.columns.insert(table.columns.end(), others.begin(), others.end());
  for (size_t r = 0; r < num_rows; ++r) {
    const JsonCursor row = rows.At(r);
    std::vector<std::string> cells;
    for (const std::string& column : table.columns) {
      cells.push_back(row.Has(column) ? FormatCell(row.Field(column)) : "");
    }
    table.rows.push_back(std::move(cells));
  }
  return table;
}

std::string EvalColumnHeading(const std::string& key) {
  static const std::map<std::string, std::string> kHeadings = {
      {"clip", "clip"},       {"view", "view"},       {"succ", "Succ"},
      {"e2d_px", "E2D (px)"}, {"e3d_mm", "E3D (mm)"}, {"jitter", "jitter"}};
  auto it = kHeadings.find(key);
  return it == kHeadings.end() ? key : it->second;
}

std::string MakeReportHtml(const ReportContents& contents) {
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>" +
      EscapeHtml(contents.title) + "</title>\n<style>" + kStyle +
      "</style>\n</head>\n<body>\n<h1>" + EscapeHtml(contents.title) +
      "</h1>\n<p class=\"meta\">Generated " + EscapeHtml(Timestamp()) +
      " by mimic2d report.</p>\n";
  html += "<h2>Evaluation</h2>\n";
  if (contents.eval) {
    AppendEvalTable(*contents.eval, &html);
  } else {
    html += "<p>No evaluation file was given.</p>\n";
  }
  html += "<h2>Training curves and figures</h2>\n";
  if (contents.image_paths.empty()) html += "<p>No figures.</p>\n";
  for (const std::string& path : contents.image_paths) {
    const std::string name = std::filesystem::path(path).filename().string();
    html += "<figure><img src=\"" + DataUri(path, false) + "\" alt=\"" +
            EscapeHtml(name) + "\"><figcaption>" + EscapeHtml(name) +
            "</figcaption></figure>\n";
  }
  html += "<h2>Videos</h2>\n";
  if (contents.video_paths.empty()) html += "<p>No videos.</p>\n";
  for (const std::string& path : contents.video_paths) {
    const std::string name = std::filesystem::path(path).filename().string();
    html +=
        "<figure><video controls muted loop playsinline preload=\"auto\" "
        "src=\"" +
        DataUri(path, true) + "\"></video><figcaption>" + EscapeHtml(name) +
        "</figcaption></figure>\n";
  }
  html +=
      "<p id=\"media-check\">media check: not run (JavaScript is off)</p>\n"
      "<script>" +
      std::string(kMediaCheckScript) + "</script>\n</body>\n</html>\n";
  return html;
}

void WriteReport(const std::string& path, const ReportContents& contents) {
  WriteFileAtomic(path, MakeReportHtml(contents));
}

}  // namespace m2d
