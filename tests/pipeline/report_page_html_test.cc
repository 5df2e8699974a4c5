// report.html's text for a mesh too large to embed (the page in a browser: report_page_test.sh).
#include "pipeline/report_page.h"

#include <gtest/gtest.h>

namespace raycarve {
namespace {

TEST(ReportPageHtml, AMeshTooLargeToEmbedIsNamedNotEmbedded) {
  ReportPageContent content;
  content.title = "model";
  content.summary = "carved";
  content.glb_name = "mesh.glb";
  content.glb_bytes_not_embedded = kMaxEmbeddedGlbBytes + 1;
  const std::string html = ReportPageHtml(content);
  EXPECT_NE(html.find("mesh.glb (268 MB) is too large to show"), std::string::npos) << html;
  EXPECT_EQ(html.find("model-data"), std::string::npos);
  EXPECT_EQ(html.find("id=\"view-status\""), std::string::npos);
  // A small mesh is embedded (where the viewer's scripts were built in) or named.
  content.glb_bytes_not_embedded = 0;
  content.glb = {'g', 'l', 'T', 'F'};
  const std::string small = ReportPageHtml(content);
  EXPECT_EQ(small.find("too large to show"), std::string::npos);
  EXPECT_NE(small.find(ReportPageHasViewer() ? "model-data" : "Open mesh.glb"), std::string::npos);
}

}  // namespace
}  // namespace raycarve
