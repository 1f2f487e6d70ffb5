// The fixed text of report.html (report_page.cpp): the page before the data and after it.
#pragma once

namespace buckle::scene {

/// Everything before the page's data: doctype, styles, the layout and the opening script tag.
extern const char* const kReportHead;
/// Everything after the data: the script that draws diagrams, shapes and the table.
extern const char* const kReportTail;

}  // namespace buckle::scene
