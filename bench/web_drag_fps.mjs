// Frames per second of the web page's view during a scripted 2 s drag, by approximation size.
//
// Starts `build/bin/limn serve` on a free loopback port and Debian's chromium (playwright-core
// from build/browser-tests, as the browser tests), opens the page at 1240 x 800 (pictures of
// 912 x 726) on the creased torus at 2, 4, 5 and 6 iterations (3,072 to 786,432 triangles),
// waits until the page holds the approximation's triangles (or, above the page's local limit,
// is ready for server previews), then moves the mouse for 2 s with the button down, one move
// every 16 ms, and prints how many frames the page showed per second: the ones it drew itself
// (WebGL) and the server previews that landed. bench/web_drag_fps.md keeps the last run.
//
//   node bench/web_drag_fps.mjs [--levels 2,4,5,6] [--seconds 2] [--window 1240x800]
import { spawn } from "node:child_process";
import { createRequire } from "node:module";
import path from "node:path";
import { fileURLToPath } from "node:url";

const root = path.dirname(path.dirname(fileURLToPath(import.meta.url)));
const args = process.argv.slice(2);
const option = (name, fallback) => {
  const k = args.indexOf(`--${name}`);
  return k >= 0 ? args[k + 1] : fallback;
};
const levels = option("levels", "2,4,5,6").split(",").map(Number);
const seconds = Number(option("seconds", "2"));
const [width, height] = option("window", "1240x800").split("x").map(Number);
const require = createRequire(path.join(root, "build/browser-tests/node_modules/index.js"));
const { chromium } = require("playwright-core");

const server = spawn(path.join(root, "build/bin/limn"), ["serve", "--listen", "127.0.0.1:0"],
                     { stdio: ["ignore", "pipe", "ignore"] });
const base = await new Promise((resolve) => {
  let out = "";
  server.stdout.on("data", (chunk) => {
    out += chunk;
    const match = out.match(/listening on (http:\/\/\S+)/);
    if (match) resolve(match[1]);
  });
});
const browser = await chromium.launch({
  executablePath: process.env.LIMN_CHROMIUM || "/usr/bin/chromium",
  args: ["--no-sandbox", "--disable-dev-shm-usage"],
});

console.log("| iterations | triangles | drag view | frames/s shown  drag end to full picture (ms) |");
console.log("| --- | --- | --- | --- | --- |");
for (const level of levels) {
  const page = await browser.newPage({ viewport: { width, height } });
  await page.goto(`${base}/?example=torus_creased&level=${level}`);
  await page.waitForFunction(() => window.limnPage.renders >= 1 && !window.limnPage.busy, null,
                             { timeout: 300_000 });
  const triangles = await page.evaluate(() => window.limnPage.lastAnswer.stats.triangles);
  // Above its local limit (a method it cannot draw coarser) the page previews with renders.
  const local = await page.waitForFunction(() => window.limnPage.localReady, null,
                                           { timeout: 60_000 }).then(() => true, () => false);
  const box = await page.locator("#view").boundingBox();
  const x = box.x + box.width / 2, y = box.y + box.height / 2;
  await page.mouse.move(x, y);
  await page.mouse.down();
  const before = await page.evaluate(() => ({ ...window.limnPage }));
  const started = Date.now();
  let i = 0;
  while (Date.now() - started < seconds * 1000) {
    i += 1;
    await page.mouse.move(x + 100 * Math.sin(i / 20), y + 20 * Math.cos(i / 20));
    await page.waitForTimeout(16);
  }
  const elapsed = (Date.now() - started) / 1000;
  const during = await page.evaluate(() => ({ ...window.limnPage }));
  await page.mouse.up();
  await page.waitForFunction((n) => window.limnPage.renders > n && !window.limnPage.busy,
                             during.renders, { timeout: 300_000 });
  const toFull = await page.evaluate(() => window.limnPage.dragToFullMs);
  const frames = local ? during.localFrames - before.localFrames : during.previews - before.previews;
  const view = local ? `local, ${during.dragTriangles.toLocaleString("en")} triangles`
                     : "server previews";
  console.log(`| ${level} | ${triangles.toLocaleString("en")} | ${view} | ` +
              `${(frames / elapsed).toFixed(1)} (${frames} in ${elapsed.toFixed(1)} s, ${i} moves) | ` +
              `${toFull.toFixed(0)} |`);
  await page.close();
}
await browser.close();
server.kill("SIGTERM");
