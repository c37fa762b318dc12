// What the browser tests share: check() and testPage(), which opens a page
// written by c3po in headless Chromium (Playwright), waits until the page says
// it is ready (document.body.dataset.ready === '1'), runs the test's own
// checks and then requires that the page logged no console error and
// requested nothing from the network (the pages are self-contained).
import path from 'node:path';
import { pathToFileURL } from 'node:url';

// Prints "ok: MESSAGE", or fails the test with "FAIL: MESSAGE".
export function check(condition, message) {
  if (!condition) {
    console.error('FAIL: ' + message);
    process.exitCode = 1;
    throw new Error(message);
  }
  console.log('ok: ' + message);
}

// testPage(PLAYWRIGHT_CORE_DIR, PAGE.html, {profileDir, viewport, acceptDownloads, readyTimeout}, async page => ...)
// Any exception (a failed check included) fails the test; the browser is
// always closed.
export async function testPage(playwrightDir, pagePath, options, test) {
  const playwright = pathToFileURL(path.join(playwrightDir, 'node_modules/playwright-core/index.mjs')).href;
  const { chromium } = await import(playwright);
  const context = await chromium.launchPersistentContext(options.profileDir, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    acceptDownloads: !!options.acceptDownloads,
    viewport: options.viewport,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
           '--disable-background-networking', '--disable-component-update', '--disable-sync',
           '--enable-unsafe-swiftshader'],
  });
  try {
    const page = context.pages()[0] || await context.newPage();
    const errors = [];
    const requests = [];
    page.on('console', message => { if (message.type() === 'error') errors.push(message.text()); });
    page.on('pageerror', error => errors.push(error.message));
    page.on('request', request => {
      const url = request.url();
      if (!url.startsWith('file:') && !url.startsWith('blob:') && !url.startsWith('data:')) requests.push(url);
    });
    await page.goto(pathToFileURL(path.resolve(pagePath)).href);
    await page.waitForFunction(() => document.body.dataset.ready === '1', null, {timeout: options.readyTimeout});

    await test(page);

    check(errors.length === 0, 'no console errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
    check(requests.length === 0, 'no network requests' + (requests.length ? ': ' + requests.join(' ') : ''));
  } catch (error) {
    if (!process.exitCode) {
      console.error('FAIL: ' + error.message);
      process.exitCode = 1;
    }
  } finally {
    await context.close();
  }
}
