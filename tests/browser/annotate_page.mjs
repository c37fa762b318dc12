// Browser test of the annotation page written by `c3po annotate --html`.
// Usage: node annotate_page.mjs PLAYWRIGHT_CORE_DIR PAGE.html EXPECTED_KEYPOINTS BOX_X,BOX_Y,BOX_Z DOWNLOAD.json
// The page shows an axis-aligned box [0,X]x[0,Y]x[0,Z]. Checks: no console
// errors, the right number of keypoints, a real mouse click on the surface
// adds one keypoint on the box surface, a click on a keypoint removes it with
// indicator sets remapped (sets containing it dropped), and the download
// button yields the object JSON (saved to DOWNLOAD.json for `c3po annotate --edit`).
import path from 'node:path';
import { check, testPage } from './page_harness.mjs';

const [playwrightDir, pagePath, expectedText, boxText, downloadPath] = process.argv.slice(2);
const expected = Number(expectedText);
const box = boxText.split(',').map(Number);

// Distance of p to the surface of the box [0,X]x[0,Y]x[0,Z] (p inside or on it).
function boxSurfaceDistance(p) {
  let inside = true, best = Infinity;
  for (let k = 0; k < 3; ++k) {
    if (p[k] < -1e-6 || p[k] > box[k] + 1e-6) inside = false;
    best = Math.min(best, Math.abs(p[k]), Math.abs(box[k] - p[k]));
  }
  return inside ? best : Infinity;
}

// The removal rule, written independently of the page: sets containing the
// removed index are dropped, larger indices shift down.
function expectedSetsAfterRemoving(sets, i) {
  return sets.filter(s => !s.includes(i)).map(s => s.map(j => (j > i ? j - 1 : j)));
}

const options = {profileDir: path.join(path.dirname(downloadPath), 'chromium-profile'),
                 viewport: {width: 1000, height: 700}, acceptDownloads: true, readyTimeout: 30000};
await testPage(playwrightDir, pagePath, options, async page => {
  check(await page.evaluate(() => !!window.c3poDebug), 'the 3D view was created (WebGL available)');

  const count = () => page.evaluate(() => window.c3poState.keypoints.length);
  check(await count() === expected, `page shows ${expected} keypoints`);
  check(await page.locator('.label').count() === expected, 'one label per keypoint');
  check(await page.locator('#keypoint-list li').count() === expected, 'one list row per keypoint');

  // A real click on the surface adds one keypoint on the surface.
  const surfacePixel = await page.evaluate(() => window.c3poDebug.meshPixel());
  check(surfacePixel !== null, 'found a pixel on the mesh away from the keypoints');
  await page.mouse.click(surfacePixel.x, surfacePixel.y);
  await page.waitForFunction(n => window.c3poState.keypoints.length === n, expected + 1, {timeout: 5000});
  const added = await page.evaluate(() => window.c3poState.keypoints.at(-1));
  check(boxSurfaceDistance(added) < 1e-5, `added keypoint [${added}] lies on the box surface`);

  // A real click on a keypoint that belongs to an indicator set removes it.
  const before = await page.evaluate(() => JSON.parse(JSON.stringify(window.c3poState)));
  let target = -1, pixel = null;
  const order = [...before.keypoints.keys()].sort((a, b) =>
    Number(before.indicator_sets.some(s => s.includes(b))) - Number(before.indicator_sets.some(s => s.includes(a))));
  for (const i of order) {
    const p = await page.evaluate(j => window.c3poDebug.keypointPixel(j), i);
    if (p.visible) { target = i; pixel = p; break; }
  }
  check(target >= 0, `keypoint ${target} is visible for a click`);
  await page.mouse.click(pixel.x, pixel.y);
  await page.waitForFunction(n => window.c3poState.keypoints.length === n, expected, {timeout: 5000});
  const after = await page.evaluate(() => JSON.parse(JSON.stringify(window.c3poState)));
  const kept = before.keypoints.filter((_, i) => i !== target);
  check(JSON.stringify(after.keypoints) === JSON.stringify(kept), `clicking keypoint ${target} removed exactly it`);
  check(JSON.stringify(after.indicator_sets) ===
        JSON.stringify(expectedSetsAfterRemoving(before.indicator_sets, target)),
        `indicator sets remapped: ${JSON.stringify(before.indicator_sets)} -> ${JSON.stringify(after.indicator_sets)}`);

  // The download button yields the object JSON.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#download')]);
  await download.saveAs(downloadPath);
  const saved = JSON.parse(await (await import('node:fs/promises')).readFile(downloadPath, 'utf8'));
  check(saved.keypoints.length === expected && JSON.stringify(saved.indicator_sets) === JSON.stringify(after.indicator_sets),
        'downloaded JSON has the page state');
});
