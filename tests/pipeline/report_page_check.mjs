// Opens a carve's report.html from disk in headless Chromium (playwright-core, Debian's chromium)
// and checks what a user would see: the page loads without console errors, the 3D view reports
// "ready", and the view's pixels show a model (not a blank canvas). Writes a screenshot of the
// view alone. Usage: node report_page_check.mjs <report.html> <screenshot.png>
// Exits 0 when every check holds, 1 with one line per failure otherwise.
import { createRequire } from 'node:module';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const require = createRequire(import.meta.url);
const viewerDir = process.env.RAYCARVE_VIEWER_DIR;
const { chromium } = require(require.resolve('playwright-core', { paths: [viewerDir] }));

const [page_path, screenshot_path] = process.argv.slice(2);
const url = pathToFileURL(path.resolve(page_path)).href;
const failures = [];
const browser = await chromium.launch({
  executablePath: process.env.RAYCARVE_CHROMIUM || '/usr/bin/chromium',
  // WebGL on the CPU (no GPU on the test machines); --no-sandbox for root in containers.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  const errors = [];
  let page = null;
  // The whole page, then the view alone (a new page: a changed #hash does not reload).
  for (const address of [url, url + '#view']) {
    page = await browser.newPage({ viewport: { width: 800, height: 600 } });
    page.on('console', (message) => { if (message.type() === 'error') errors.push(message.text()); });
    page.on('pageerror', (error) => errors.push(String(error)));
    await page.goto(address);
    await page.waitForSelector('#view-status:not([data-state="loading"])', { state: 'attached', timeout: 120000 });
    const state = await page.$eval('#view-status', (e) => [e.dataset.state, e.textContent]);
    if (state[0] !== 'ready') failures.push(`${address}: the 3D view says "${state[1]}"`);
  }
  if (errors.length > 0) failures.push(`console errors: ${errors.join(' | ')}`);
  // The canvas as drawn (preserveDrawingBuffer): the share of pixels that differ from the
  // background and how many colours they take (a model, not a flat silhouette).
  const figures = await page.evaluate(() => {
    const canvas = document.getElementById('view');
    const copy = document.createElement('canvas');
    copy.width = canvas.width;
    copy.height = canvas.height;
    const context = copy.getContext('2d');
    context.drawImage(canvas, 0, 0);
    const data = context.getImageData(0, 0, copy.width, copy.height).data;
    let model = 0;
    const colours = new Set();
    for (let i = 0; i < data.length; i += 4) {
      const d = Math.abs(data[i] - 0x20) + Math.abs(data[i + 1] - 0x24) + Math.abs(data[i + 2] - 0x2a);
      if (d > 24) {
        ++model;
        colours.add((data[i] >> 4) * 256 + (data[i + 1] >> 4) * 16 + (data[i + 2] >> 4));
      }
    }
    return { width: copy.width, height: copy.height, share: model / (copy.width * copy.height), colours: colours.size };
  });
  console.log(`3D view ${figures.width}x${figures.height}: ${(100 * figures.share).toFixed(1)}% of ` +
              `its pixels show the model, in ${figures.colours} colours (of 4096 levels)`);
  if (figures.share < 0.05) failures.push(`the model covers ${(100 * figures.share).toFixed(2)}% of the view (< 5%)`);
  if (figures.colours < 32) failures.push(`the model shows ${figures.colours} colours (< 32): not the photos' texture`);
  await page.screenshot({ path: screenshot_path });
} finally {
  await browser.close();
}
for (const failure of failures) console.log(`FAILED: ${failure}`);
process.exit(failures.length > 0 ? 1 : 0);
