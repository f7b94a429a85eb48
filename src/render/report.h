// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_REPORT_H_
#define MIMIC2D_RENDER_REPORT_H_

#include <optional>
#include <string>
#include <vector>

namespace m2d {

// An evaluation table read from JSON (docs/rendering.md):
//   {"rows": [{"clip": ..., "view": ..., "succ": ..., "e2d_px": ...,
//              "e3d_mm": ..., "jitter": ...}, ...]}
// Any keys are accepted; the known ones come first, in that order, the
// others after them in order of first appearance. Cells are formatted text.
struct EvalTable {
  std::vector<std::string> columns;            // JSON keys
  std::vector<std::vector<std::string>> rows;  // formatted cells
};

// InputError naming the file and the field (e.g. rows[3].e2d_px) when the
// file is not of that shape or a value is not a string, number, bool or
// null.
EvalTable ReadEvalTable(const std::string& json_path);

// Column heading for a JSON key ("e2d_px" -> "E2D (px)").
std::string EvalColumnHeading(const std::string& key);

struct ReportContents {
  std::string title = "mimic2d run";
  std::optional<EvalTable> eval;
  std::vector<std::string> image_paths;  // PNG, JPEG, GIF or SVG files
  std::vector<std::string> video_paths;  // MP4 or WebM files
};

// One self-contained HTML page: images and videos embedded as base64 data
// URIs, no external references, so it opens offline and can be mailed. A
// small inline script reports in the page whether every image and video
// decoded (the "media check" line). InputError naming a missing or
// unsupported media file.
std::string MakeReportHtml(const ReportContents& contents);
// MakeReportHtml, written atomically.
void WriteReport(const std::string& path, const ReportContents& contents);

}  // namespace m2d

#endif  // MIMIC2D_RENDER_REPORT_H_
