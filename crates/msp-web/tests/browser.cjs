// The browser tuner in headless Chromium (scripts/web-test runs it): the page
// is loaded from a loopback server, a plant typed, a slider moved, the numbers
// read back from their ids and checked against `msp run` of the same pairs.
//
// usage: node browser.cjs BASE_URL MSP_BIN SCREENSHOT.png
// env: PLAYWRIGHT_CORE (the playwright-core package's folder), CHROMIUM.
//
// The page's engine is WebAssembly: its sin, cos, exp and log are Rust's
// libm where the CLI's are the host C library's, each within an ulp of the
// exact value and not always the same one, so a figure may differ in its
// last bits; the numbers are compared to a relative 1e-9 (the simulation
// and the margins amplify an ulp by far less than 10^6), and natively the
// same engine equals the CLI bit for bit (crates/msp-cli/tests/web.rs).

'use strict';
const { chromium } = require(process.env.PLAYWRIGHT_CORE || 'playwright-core');
const { execFileSync } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');
const assert = require('assert');

const [base, mspBin, shot] = process.argv.slice(2);
const IDS = ['kp', 'ti', 'td', 'lambda', 'ms', 'pm', 'gm', 'dm'];
const TOL = 1e-9;
const BUDGET_MS = 50;

function close(a, b, what) {
  if (a === b) return;
  const ok = Number.isFinite(a) && Number.isFinite(b) && Math.abs(a - b) <= TOL * Math.max(Math.abs(a), Math.abs(b), 1e-300);
  assert.ok(ok, `${what}: page ${a}, CLI ${b}`);
}

/** `msp run` of the pairs: its report and CSV text. */
function cli(pairs) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'msp-web-'));
  const report = path.join(dir, 'r.json');
  const csv = path.join(dir, 'r.csv');
  const args = ['run'];
  for (const [k, v] of pairs) args.push(`--${k}`, v);
  args.push('--report', report, '-o', csv, '-q');
  execFileSync(mspBin, args);
  const out = { report: JSON.parse(fs.readFileSync(report, 'utf8')), csv: fs.readFileSync(csv, 'utf8') };
  fs.rmSync(dir, { recursive: true });
  return out;
}

/** The numbers the page shows, read from their ids. */
async function shown(page) {
  return page.evaluate((ids) => Object.fromEntries(ids.map((i) => [i, document.getElementById(i).textContent])), IDS);
}

/** The page's numbers against `msp run` of the page's own pairs. */
async function agrees(page, what) {
  const pairs = await page.evaluate(() => window.msp.pairs());
  const { report, csv } = cli(pairs);
  const nums = await shown(page);
  const params = report.controller.params;
  for (const k of ['kp', 'ti', 'td', 'lambda']) {
    if (params[k] === undefined) assert.strictEqual(nums[k], '', `${what}: ${k}`);
    else close(Number(nums[k]), params[k], `${what}: ${k}`);
  }
  for (const k of ['ms', 'pm', 'gm', 'dm']) close(Number(nums[k]), report.robustness[k], `${what}: ${k}`);
  // the simulated samples, every one
  const mine = (await page.evaluate(() => window.msp.csv())).trim().split('\n');
  const theirs = csv.trim().split('\n');
  assert.strictEqual(mine[0], theirs[0], `${what}: CSV header`);
  assert.strictEqual(mine.length, theirs.length, `${what}: CSV rows`);
  for (let i = 1; i < mine.length; i++) {
    const a = mine[i].split(',').map(Number);
    const b = theirs[i].split(',').map(Number);
    // a sample is compared on the scale of its column's signal
    a.forEach((x, j) => {
      if (x !== b[j]) {
        assert.ok(Math.abs(x - b[j]) <= TOL * Math.max(1, Math.abs(b[j])), `${what}: CSV row ${i} column ${j}: ${x} vs ${b[j]}`);
      }
    });
  }
  const last = await page.evaluate(() => window.msp.last().report);
  assert.strictEqual(last.samples, report.samples);
  assert.strictEqual(last.stable, report.stable);
  assert.deepStrictEqual(Object.keys(last).sort(), Object.keys(report).sort(), `${what}: the report's keys`);
  console.log(`ok: ${what}: ${pairs.map(([k, v]) => `--${k} ${v}`).join(' ')} (${mine.length - 1} samples)`);
  return report;
}

async function ready(page) {
  await page.waitForFunction(() => ['ready', 'failed'].includes(document.body.dataset.state), null, { timeout: 60000 });
  assert.strictEqual(await page.evaluate(() => document.body.dataset.state), 'ready');
}

(async () => {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox'],
  });
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: base });
  const page = await context.newPage();
  const requests = [];
  const errors = [];
  page.on('request', (r) => requests.push(r.url()));
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));

  // 1. a link opens its design: the README's plant with a Smith predictor
  await page.goto(`${base}/?plant=0.2/s*e^-7.4s&controller=smith`);
  await ready(page);
  await agrees(page, 'a link');

  // 2. a plant typed with an error shows the column, as the CLI does
  await page.fill('#plant', '0.2/s*e^-7.4');
  await page.press('#plant', 'Tab');
  const err = await page.textContent('#plant-error');
  assert.ok(/at column 13/.test(err) && err.includes('\n            ^'), err);
  assert.strictEqual(await page.getAttribute('#plant', 'aria-invalid'), 'true');
  assert.deepStrictEqual(Object.values(await shown(page)), IDS.map(() => ''), 'no number for a failed design');
  const cliErr = (() => {
    try {
      execFileSync(mspBin, ['run', '--plant', '0.2/s*e^-7.4'], { stdio: 'pipe' });
    } catch (e) {
      return e.stderr.toString();
    }
    return '';
  })();
  assert.ok(cliErr.includes(err.split(' at column')[0]), `${err}\n${cliErr}`);
  console.log('ok: a plant with an error shows its column');

  // 3. a plant typed, then a slider moved by the keyboard
  await page.fill('#plant', '1.6e^-6s/(10s+1)');
  await page.press('#plant', 'Tab');
  await ready(page);
  const schemes = await page.$$eval('#controller option', (os) => os.map((o) => o.value));
  assert.ok(schemes.includes('smith') && schemes.includes('filtered-smith') && !schemes.includes('karan-dey'), schemes.join());
  const before = await shown(page);
  await page.focus('#speed');
  for (let i = 0; i < 6; i++) await page.keyboard.press('ArrowRight');
  const after = await shown(page);
  assert.ok(Number(after.lambda) > Number(before.lambda), `λ ${before.lambda} → ${after.lambda}`);
  assert.ok(page.url().includes('lambda='), page.url());
  await agrees(page, 'a typed plant, the response-time slider moved');
  await page.focus('#robustness');
  for (let i = 0; i < 10; i++) await page.keyboard.press('ArrowRight');
  const robust = await shown(page);
  assert.ok(Number(robust.ms) < Number(after.ms), `Ms ${after.ms} → ${robust.ms}`);
  assert.ok(page.url().includes('lambda='), page.url());
  await agrees(page, 'the robustness slider moved');

  // 4. the link reopens the same design
  const nums = await shown(page);
  await page.goto(page.url());
  await ready(page);
  assert.deepStrictEqual(await shown(page), nums);
  console.log('ok: the URL reopens the design');

  // 5. two targets, as pidtune: MathWorks' dead-time example
  await page.goto(`${base}/?plant=5.6e^-93.9s/(40.2s%2B1)&controller=pi&target=wc=0.006,pm=60`);
  await ready(page);
  const pid = await shown(page);
  assert.strictEqual(Number(Number(pid.kp).toPrecision(3)), 0.0501, pid.kp);
  assert.strictEqual(Number(Number(pid.ti).toPrecision(3)), 47.3, pid.ti);
  await agrees(page, 'pidtune\'s two targets');

  // 6. exports: the CSV, the report (the CLI's schema), the SVG, the command
  await page.goto(`${base}/?plant=2.3e^-8s/(15s%2B1)&controller=smith&lambda=8&ts=0.1&duration=900&setpoint=1@0&setpoint=0@600&disturbance=input:0.2@300&event=450:plant-dead-time%3D11&noise=0.02&seed=1&umin=-1&umax=1.5`);
  await ready(page);
  const report = await agrees(page, 'events, noise and actuator limits');
  const saved = async (button) => {
    const [d] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
    return fs.readFileSync(await d.path(), 'utf8');
  };
  assert.strictEqual(await saved('#export-csv'), await page.evaluate(() => window.msp.csv()));
  const json = JSON.parse(await saved('#export-json'));
  assert.deepStrictEqual(Object.keys(json).sort(), Object.keys(report).sort());
  assert.deepStrictEqual(json.scenario.events, report.scenario.events);
  const svg = await saved('#export-svg');
  assert.ok(svg.startsWith('<svg xmlns="http://www.w3.org/2000/svg"') && svg.includes('<polyline'), svg.slice(0, 80));
  await page.click('#copy-command');
  const copied = await page.evaluate(() => navigator.clipboard.readText());
  assert.strictEqual(copied, await page.inputValue('#command'));
  const line = copied.replace(/^msp /, `'${mspBin}' `) + ' --report /dev/stdout -q -o /dev/null';
  const rerun = JSON.parse(execFileSync('sh', ['-c', line]).toString());
  assert.deepStrictEqual(rerun.controller, report.controller);
  console.log('ok: the exports and the copied command');

  // 7. speed: a slider move re-tunes, re-runs and redraws a 10 001-sample
  // run (the duration given: msp's own would grow with a slower tuning)
  await page.goto(`${base}/?plant=0.2/s*e^-7.4s&controller=smith&ts=0.0074&duration=74&setpoint=1@0&disturbance=input:-0.1@37`);
  await ready(page);
  const samples = await page.evaluate(() => window.msp.last().report.samples);
  assert.strictEqual(samples, 10001);
  for (const [id, values] of [
    ['speed', [0.4, 0.8, 1.2, 0.6, 0.2, -0.2, -0.6, 0.3, 0.9, 1.5, 0.1]],
    ['robustness', [0.2, 0.35, 0.5, 0.65, 0.8, 0.9, 0.7, 0.55, 0.4, 0.25, 0.1]],
  ]) {
    const times = await page.evaluate(async ([id, values]) => {
      const s = document.getElementById(id);
      const out = [];
      for (const v of values) {
        s.value = v;
        s.dispatchEvent(new Event('input'));
        out.push(window.msp.timing());
        if (window.msp.last().report.samples !== 10001) throw new Error('not a 10 001-sample run');
        await new Promise((r) => requestAnimationFrame(() => r()));
      }
      return out;
    }, [id, values]);
    const sorted = times.slice(1).sort((a, b) => a - b);
    const median = sorted[Math.floor(sorted.length / 2)];
    console.log(`${id} slider move on ${samples} samples: median ${median.toFixed(1)} ms, slowest ${sorted[sorted.length - 1].toFixed(1)} ms (re-tune, re-run, redraw)`);
    assert.ok(median <= BUDGET_MS, `${id}: median ${median} ms > ${BUDGET_MS} ms`);
  }

  // 8. plain and accessible: every control named, the keyboard reaches them
  const unnamed = await page.evaluate(() =>
    [...document.querySelectorAll('input, select, textarea, button')]
      .filter((el) => {
        if (el.type === 'radio') return !el.closest('label');
        const label = el.id && document.querySelector(`label[for="${el.id}"]`);
        return !label && !el.getAttribute('aria-label') && !el.textContent.trim();
      })
      .map((el) => el.id || el.outerHTML));
  assert.deepStrictEqual(unnamed, []);
  await page.focus('body');
  const reached = new Set();
  for (let i = 0; i < 40; i++) {
    await page.keyboard.press('Tab');
    reached.add(await page.evaluate(() => document.activeElement.id));
  }
  for (const id of ['plant', 'controller', 'speed', 'robustness', 'ts', 'event', 'export-csv', 'copy-command']) {
    assert.ok(reached.has(id), `Tab does not reach #${id}`);
  }
  const outside = requests.filter((u) => !u.startsWith(base) && !u.startsWith('data:') && !u.startsWith('blob:'));
  assert.deepStrictEqual(outside, [], 'the page asks only its own folder');
  assert.deepStrictEqual(errors, []);
  console.log('ok: labels, keyboard, no request outside its folder, no console error');

  // 9. readable on a phone's width, and the README's screenshot at 1280x800
  await page.setViewportSize({ width: 390, height: 844 });
  await page.goto(`${base}/?plant=0.2/s*e^-7.4s&controller=smith`);
  await ready(page);
  const wide = await page.evaluate(() => document.documentElement.scrollWidth);
  assert.ok(wide <= 391, `the page is ${wide} px wide on a 390 px screen`);
  await page.setViewportSize({ width: 1280, height: 800 });
  await page.goto(`${base}/?plant=1.6e^-6s/(10s%2B1)&controller=smith&lambda=6&ts=0.05&duration=450&disturbance=input:0.2@150&event=300:plant-dead-time%3D7`);
  await ready(page);
  assert.ok(await page.evaluate(() => window.msp.last() !== null), await page.textContent('#status'));
  await page.screenshot({ path: shot, fullPage: true });
  console.log(`ok: a phone's width; screenshot ${shot}`);
  await browser.close();
})().catch((e) => {
  console.error(e);
  process.exit(1);
});
