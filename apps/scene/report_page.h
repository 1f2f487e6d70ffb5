// The fixed text of report.html around its data, embedded at build time from the page, its styles
// and its script in apps/scene/report/ (report.html, report.css, report.js; cmake/embed_report.cmake).
// report.cpp writes kReportHead, the page's data, kReportMiddle, kReportScript, kReportEnd.
#pragma once

namespace buckle::scene {

/// Everything before the page's data: doctype, styles, the layout and the data's script tag.
extern const char* const kReportHead;
/// Between the data and the script: the data's closing tag and the script's opening one.
extern const char* const kReportMiddle;
/// The script that draws the diagrams, shapes and tables in the browser (report.js).
extern const char* const kReportScript;
/// After the script: the page's end.
extern const char* const kReportEnd;

}  // namespace buckle::scene
