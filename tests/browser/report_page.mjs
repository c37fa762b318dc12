// Browser test of the evaluation report written by `c3po eval --report`.
// Usage: node report_page.mjs PLAYWRIGHT_CORE_DIR REPORT.html EXPECTED_ROWS|certify PROFILE_DIR
// Checks: loads without console errors or network requests; the results
// table has EXPECTED_ROWS rows; the soundness section and the SVG plots are
// there; the 3D view has a WebGL canvas that draws points (non-background
// pixels), a mouse drag orbits the camera, the example buttons switch views
// and every rejected example names why it was refused.
import { check, testPage } from './page_harness.mjs';

const [playwrightDir, pagePath, rowsText, profileDir] = process.argv.slice(2);
// EXPECTED_ROWS "certify": the page of `c3po certify --report` (no results table).
const certifyReport = rowsText === 'certify';
const expectedRows = Number(rowsText);

const options = {profileDir, viewport: {width: 1200, height: 900}, readyTimeout: 60000};
await testPage(playwrightDir, pagePath, options, async page => {
  if (certifyReport) {
    const rows = await page.locator('table#refusals tbody tr').count();
    check(rows >= 2, `refusal table lists certified and refused poses (${rows} rows)`);
  } else {
    const rows = await page.locator('table#results tbody tr').count();
    check(rows === expectedRows, `results table has ${expectedRows} rows (found ${rows})`);
    check(await page.locator('#soundness #false-certificates').count() === 1, 'soundness figure present');
    check(await page.locator('#adds-plots svg.chart').count() >= 2, 'ADD-S plots present');
  }

  const state = await page.evaluate(() => ({views: window.c3poReport.views, webgl: window.c3poReport.webgl,
                                             error: window.c3poReport.error}));
  check(state.views > 0, `${state.views} 3D examples in the page`);
  check(state.webgl === true, '3D view created (WebGL available)' + (state.error ? ': ' + state.error : ''));
  const canvas = page.locator('#view3d canvas');
  check(await canvas.count() === 1, 'one 3D canvas');
  await canvas.scrollIntoViewIfNeeded();
  const box = await canvas.boundingBox();
  check(box && box.width > 200 && box.height > 200, `canvas is ${box && box.width}x${box && box.height}`);

  // The view draws something: count non-background pixels of a fresh frame.
  const framesBefore = await page.evaluate(() => { window.c3poReport.measure = true; window.c3poReport.show(0); return window.c3poReport.frames; });
  await page.waitForFunction(n => window.c3poReport.frames > n, framesBefore, {timeout: 10000});
  const coloured = await page.evaluate(() => window.c3poReport.coloured);
  check(coloured > 200, `the 3D view draws the example (${coloured} non-background pixels)`);

  // A mouse drag orbits the camera.
  const theta = await page.evaluate(() => window.c3poReport.orbit.theta);
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 120, box.y + box.height / 2 + 30, {steps: 6});
  await page.mouse.up();
  const thetaAfter = await page.evaluate(() => window.c3poReport.orbit.theta);
  check(Math.abs(thetaAfter - theta) > 0.3, `drag rotates the view (theta ${theta.toFixed(2)} -> ${thetaAfter.toFixed(2)})`);

  // The example buttons switch views.
  const buttons = page.locator('#view-buttons button');
  check(await buttons.count() === state.views, 'one button per example');
  if (state.views > 1) {
    await buttons.nth(state.views - 1).click();
    check(await page.evaluate(() => window.c3poReport.shown) === state.views - 1, 'clicking a button shows its example');
    if (!certifyReport) {
      check((await page.locator('#view-info').textContent()).includes('ADD-S'), 'example info shows its ADD-S');
    }
  }

  // Every rejected example says why (the failed certificate parts), a certified one does not.
  check(await page.locator('#layer-rival').count() === 1, 'a layer for the rival pose that refused an example');
  for (let i = 0; i < state.views; ++i) {
    await page.evaluate(k => window.c3poReport.show(k), i);
    const info = await page.locator('#view-info').textContent();
    const certified = info.startsWith('CERTIFIED');
    check(info.includes('refused by ') === !certified,
          `example ${i} (${certified ? 'certified' : 'rejected'}) ${certified ? 'has no' : 'names its'} refusal`);
  }
});
