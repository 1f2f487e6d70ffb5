// The fixed text of report.html (report_page.cpp): the page before the data and after it.
#pragma once

namespace buckle::scene {

/// Everything before the page's data: doctype, styles, the layout and the opening script tag.
extern const char* const kReportHead;
/// After the data: the script's start (its error box).
extern const char* const kReportScriptStart;
/// Then the drawing functions: charts, markers, labels placed apart, jump arrows (report_chart.cpp).
extern const char* const kReportChartScript;
/// The rest: the script that lays out the diagrams, shapes and tables, and the page's end.
extern const char* const kReportTail;

}  // namespace buckle::scene
