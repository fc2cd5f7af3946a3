// Browser tests of limn's page at "/": Debian's chromium, driven by playwright-core, against the
// real `limn serve` on 127.0.0.1 (a free port). Each test does what a person would and checks
// what they would see. Screenshots go to LIMN_ARTIFACTS (build/web-artifacts); the times from
// opening the page to the first picture and from a drag's end to the full-size picture are
// printed (docs/web.md reports them).
//
// Run through CTest (label "browser") or tests/browser/run.sh, which finds node, the npm
// packages (LIMN_NODE_MODULES) and chromium first.
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import { mkdirSync, writeFileSync } from "node:fs";
import { createRequire } from "node:module";
import path from "node:path";
import { after, before, describe, it } from "node:test";

const binary = process.env.LIMN_BINARY;
const artifacts = process.env.LIMN_ARTIFACTS || "build/web-artifacts";
const require = createRequire(path.join(process.env.LIMN_NODE_MODULES, "index.js"));
const { chromium } = require("playwright-core");

let server, baseUrl, browser, page;
const timings = {};

// `limn serve` on a free port; resolves once it prints where it listens.
function startServer() {
  return new Promise((resolve, reject) => {
    server = spawn(binary, ["serve", "--listen", "127.0.0.1:0"],
                   { stdio: ["ignore", "pipe", "pipe"] });
    let out = "";
    server.stdout.on("data", (chunk) => {
      out += chunk;
      const match = out.match(/listening on (http:\/\/\S+)/);
      if (match) resolve(match[1]);
    });
    server.stderr.on("data", () => {});  // the request log
    server.on("exit", (code) => reject(new Error(`limn serve exited with ${code}: ${out}`)));
  });
}

async function shot(name, locator = page) {
  await locator.screenshot({ path: path.join(artifacts, `${name}.png`) });
}

// Waits until the page has shown `n` full-size pictures in all and has none in flight, so
// that what it shows is the answer to the latest settings (a render that was already on its
// way when a control changed may land first and count).
async function waitForRenders(n) {
  await page.waitForFunction((k) => window.limnPage.renders >= k && !window.limnPage.busy, n,
                             { timeout: 120_000 });
}

// The fraction of an <img>'s pixels that show something: opaque and not near white.
async function inkFraction(selector) {
  return page.$eval(selector, (img) => {
    const canvas = document.createElement("canvas");
    canvas.width = img.naturalWidth;
    canvas.height = img.naturalHeight;
    const ctx = canvas.getContext("2d");
    ctx.drawImage(img, 0, 0);
    const { data } = ctx.getImageData(0, 0, canvas.width, canvas.height);
    let ink = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (data[i + 3] > 128 && data[i] + data[i + 1] + data[i + 2] < 3 * 235) ink += 1;
    }
    return ink / (data.length / 4);
  });
}

// Keeps the picture's pixels in the page under `name`, for differingFraction() to compare.
async function keepPixels(selector, name) {
  await page.$eval(selector, (img, key) => {
    const canvas = document.createElement("canvas");
    canvas.width = img.naturalWidth;
    canvas.height = img.naturalHeight;
    const ctx = canvas.getContext("2d");
    ctx.drawImage(img, 0, 0);
    (window.kept ??= {})[key] = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
  }, name);
}

// Keeps the local WebGL view's current frame under `name`, as keepPixels does for a picture.
async function keepLocalSnapshot(name) {
  await page.evaluate(async () => {
    const img = new Image();
    img.src = window.limnPage.localSnapshot();
    await img.decode();
    img.id = "local-snapshot";
    img.hidden = true;
    document.body.append(img);
  });
  await keepPixels("#local-snapshot", name);
  await page.$eval("#local-snapshot", (img) => img.remove());
}

// The fraction of pixels that differ clearly between two kept pictures of the same size.
async function differingFraction(a, b) {
  return page.evaluate(([a, b]) => {
    const p = window.kept[a], q = window.kept[b];
    if (p.length !== q.length) throw new Error("pictures of different sizes");
    let differ = 0;
    for (let i = 0; i < p.length; i += 4) {
      const d = Math.abs(p[i] - q[i]) + Math.abs(p[i + 1] - q[i + 1]) +
                Math.abs(p[i + 2] - q[i + 2]) + Math.abs(p[i + 3] - q[i + 3]);
      if (d > 24) differ += 1;
    }
    return differ / (p.length / 4);
  }, [a, b]);
}

// Changes a control the way a person does (the value, then the change event).
async function set(selector, value) {
  const renders = await page.evaluate(() => window.limnPage.renders);
  await page.$eval(selector, (el, v) => {
    if (el.type === "checkbox") el.checked = v; else el.value = String(v);
    el.dispatchEvent(new Event("input", { bubbles: true }));
    el.dispatchEvent(new Event("change", { bubbles: true }));
  }, value);
  return renders;
}

const triangles = () => page.$eval("#stats", (el) => Number(el.dataset.triangles));

describe("limn's page", () => {
  before(async () => {
    mkdirSync(artifacts, { recursive: true });
    baseUrl = await startServer();
    browser = await chromium.launch({
      executablePath: process.env.LIMN_CHROMIUM || "/usr/bin/chromium",
      args: ["--no-sandbox", "--disable-dev-shm-usage"],
    });
    page = await browser.newPage({ viewport: { width: 1240, height: 800 } });
    page.on("pageerror", (error) => console.log(`page error: ${error.message}`));
  });

  after(async () => {
    await browser?.close();
    server?.kill("SIGTERM");
    writeFileSync(path.join(artifacts, "timings.json"), JSON.stringify(timings, null, 2));
  });

  it("opens with an example rendered", async () => {
    const opened = Date.now();
    await page.goto(baseUrl + "/");
    await waitForRenders(1);
    timings.firstPictureMs = Date.now() - opened;
    timings.firstPictureSinceNavigationMs = await page.evaluate(() => window.limnPage.firstPictureMs);
    console.log(`time to first picture: ${timings.firstPictureMs} ms from goto ` +
                `(${timings.firstPictureSinceNavigationMs.toFixed(0)} ms after navigation start)`);
    assert.equal(await page.$eval("#example", (el) => el.value), "torus_creased");
    const ink = await inkFraction("#picture");
    assert.ok(ink > 0.05, `the first picture is blank (${(100 * ink).toFixed(2)}% ink)`);
    assert.match(await page.textContent("#mesh-info"), /96 vertices, 96 faces/);
    await shot("first-load");
  });

  it("shows more triangles for more iterations, with the cage over the surface", async () => {
    await set("#draw-cage", true);
    await set("#shading", "flat");  // facets show the iteration count
    // Each step of the slider timed from the change to the new picture (the default engine).
    timings.iterationsSliderMs = {};
    const level = async (value) => {
      const started = Date.now();
      const n = await set("#level", value);
      await waitForRenders(n + 1);
      timings.iterationsSliderMs[value] = Date.now() - started;
    };
    await level(1);
    const one = await triangles();
    await shot("cage-level-1", page.locator("#view"));
    await level(2);
    await shot("cage-level-2", page.locator("#view"));
    await level(4);
    await level(3);
    const three = await triangles();
    await shot("cage-level-3", page.locator("#view"));
    console.log("iterations slider, change to picture (ms) by level: " +
                JSON.stringify(timings.iterationsSliderMs));
    // The torus is all quads: each level splits a quad into four, two triangles each.
    assert.equal(one, 96 * 2 * 4);
    assert.equal(three, 96 * 2 * 64);
    assert.match(await page.textContent("#stats"), /12,288 triangles/);
    const n = await set("#shading", "smooth");
    await waitForRenders(n + 1);
  });

  it("changes the picture when the cage is toggled", async () => {
    await keepPixels("#picture", "withCage");
    const n = await set("#draw-cage", false);
    await waitForRenders(n + 1);
    await keepPixels("#picture", "without");
    const changed = await differingFraction("withCage", "without");
    assert.ok(changed > 0.005, `only ${(100 * changed).toFixed(3)}% of the pixels changed`);
  });

  it("orbits on a drag: the page draws the view itself, the full picture follows", async () => {
    // The approximation's triangles arrive after a full render (POST /v1/tessellate).
    await page.waitForFunction(() => window.limnPage.localReady, null, { timeout: 60_000 });
    const azimuth = await page.$eval("#view", (el) => Number(el.dataset.azimuth));
    const { renders, previews, localFrames } = await page.evaluate(() => ({ ...window.limnPage }));
    await keepPixels("#picture", "beforeDrag");
    const box = await page.locator("#view").boundingBox();
    const x = box.x + box.width / 2, y = box.y + box.height / 2;
    await page.mouse.move(x, y);
    await page.mouse.down();
    for (let i = 1; i <= 30; i++) {
      await page.mouse.move(x + 6 * i, y + 2 * i);
      await page.waitForTimeout(30);
      if (i === 20) await shot("drag-local-view", page.locator("#view"));
    }
    await page.mouse.up();
    await waitForRenders(renders + 1);
    const state = await page.evaluate(() => ({ ...window.limnPage }));
    timings.dragToFullMs = state.dragToFullMs;
    timings.localFramesDuringDrag = state.localFrames - localFrames;
    console.log(`drag end to full-size picture: ${state.dragToFullMs.toFixed(0)} ms ` +
                `(${state.localFrames - localFrames} local frames, ` +
                `${state.previews - previews} server previews during the drag)`);
    const after = await page.$eval("#view", (el) => Number(el.dataset.azimuth));
    assert.ok(Math.abs(after - azimuth) > 45, `azimuth ${azimuth} -> ${after}`);
    assert.ok(state.localFrames - localFrames >= 10, "the page drew few frames during the drag");
    await keepPixels("#picture", "afterDrag");
    assert.ok(await differingFraction("beforeDrag", "afterDrag") > 0.01, "the view did not turn");
    // The picture is requested at the size it is shown.
    const size = await page.evaluate(() => window.limnPage.requestSize);
    assert.equal(await page.$eval("#picture", (img) => img.naturalWidth), size.width);
    assert.equal(await page.$eval("#picture", (img) => img.naturalHeight), size.height);
    assert.ok(await page.locator("#gl-canvas").isHidden(), "the local view stays over the picture");
    // The local view and the server's picture of the same camera agree: the page's orbit is
    // the server's.
    await keepLocalSnapshot("local");
    const disagree = await differingFraction("afterDrag", "local");
    console.log(`local view vs server picture: ${(100 * disagree).toFixed(2)}% of pixels differ`);
    assert.ok(disagree < 0.03, `${(100 * disagree).toFixed(2)}% of the pixels differ`);
    await page.$eval("#gl-canvas", (c) => { c.hidden = true; });
  });

  it("draws a heavy approximation coarser while dragging", async () => {
    const other = await browser.newPage({ viewport: { width: 1240, height: 800 } });
    await other.goto(baseUrl + "/?example=torus_creased&level=5");
    await other.waitForFunction(() => window.limnPage.localReady, null, { timeout: 120_000 });
    const { full, drag } = await other.evaluate(() => ({
      full: window.limnPage.lastAnswer.stats.triangles, drag: window.limnPage.dragTriangles,
    }));
    console.log(`level of detail: ${full} triangles in the picture, ${drag} while dragging`);
    assert.equal(full, 96 * 2 * 4 ** 5);
    assert.equal(drag, 96 * 2 * 4 ** 3, "the drag view is not 2 iterations coarser");
    await other.close();
  });

  it("previews a drag with small renders where it does not draw the view itself", async () => {
    const other = await browser.newPage({ viewport: { width: 1240, height: 800 } });
    await other.goto(baseUrl + "/?preview=server&example=cube");
    await other.waitForFunction(() => window.limnPage.renders >= 1 && !window.limnPage.busy);
    const box = await other.locator("#view").boundingBox();
    const x = box.x + box.width / 2, y = box.y + box.height / 2;
    await other.mouse.move(x, y);
    await other.mouse.down();
    for (let i = 1; i <= 20; i++) {
      await other.mouse.move(x - 5 * i, y);
      await other.waitForTimeout(30);
    }
    await other.mouse.up();
    await other.waitForFunction(() => window.limnPage.renders >= 2 && !window.limnPage.busy);
    const state = await other.evaluate(() => ({ ...window.limnPage }));
    console.log(`server previews: ${state.previews} during the drag, then the full picture ` +
                `${state.dragToFullMs.toFixed(0)} ms after its end`);
    assert.ok(state.previews >= 3, `${state.previews} previews`);
    assert.equal(state.localFrames, 0);
    await other.close();
  });

  it("overlays the contour from /v1/silhouette and draws the cage alone without the surface",
     async () => {
    await page.check("#draw-contours");
    await page.locator("#contours-overlay svg path").first().waitFor({ timeout: 60_000 });
    const pieces = await page.$$eval("#contours-overlay svg path",
                                     (paths) => paths.map((p) => p.getAttribute("class")));
    assert.ok(pieces.includes("visible"), `contour pieces: ${pieces}`);
    await page.uncheck("#draw-contours");
    assert.ok(await page.locator("#contours-overlay").isHidden());

    let n = await set("#draw-cage", true);
    await waitForRenders(n + 1);
    n = await set("#draw-surface", false);
    await waitForRenders(n + 1);
    assert.ok(await page.locator("#cage-canvas").isVisible(), "no cage drawn without the surface");
    assert.ok(await page.locator("#picture").evaluate((img) => getComputedStyle(img).visibility) ===
              "hidden");
    const drawn = await page.$eval("#cage-canvas", (canvas) => {
      const { data } = canvas.getContext("2d").getImageData(0, 0, canvas.width, canvas.height);
      let ink = 0;
      for (let i = 3; i < data.length; i += 4) ink += data[i] > 0;
      return ink / (data.length / 4);
    });
    assert.ok(drawn > 0.005, `the cage covers ${(100 * drawn).toFixed(2)}% of the canvas`);
    await shot("cage-without-surface", page.locator("#approx-panel"));
    n = await set("#draw-surface", true);
    await waitForRenders(n + 1);
    n = await set("#draw-cage", false);
    await waitForRenders(n + 1);
  });

  it("cancels a superseded render on the server too", async () => {
    const abandoned = async () => {
      const text = await (await fetch(baseUrl + "/metrics")).text();
      return Number(text.match(/limn_render_jobs_refused_total\{reason="abandoned"\} (\d+)/)[1]);
    };
    const before = await abandoned();
    // A slow render (the reference at 1024 px), superseded at once by a double-click (reset).
    await page.selectOption("#size", "1024");
    await page.check("#compare");
    await page.waitForTimeout(300);
    const renders = await page.evaluate(() => window.limnPage.renders);
    await page.dblclick("#view");
    await waitForRenders(renders + 1);
    let after = await abandoned();
    for (let i = 0; i < 40 && after === before; i++) {
      await page.waitForTimeout(100);
      after = await abandoned();
    }
    assert.ok(after > before, "the server finished a render nobody waited for");
    await page.uncheck("#compare");
    await page.selectOption("#size", "auto");
    await page.waitForFunction(() => document.querySelector("#progress").hidden &&
                                     document.querySelector("#picture").naturalWidth ===
                                     window.limnPage.requestSize.width,
                               null, { timeout: 60_000 });
  });

  it("says what is wrong with an uploaded broken OBJ, next to the mesh controls", async () => {
    await page.setInputFiles("#upload", {
      name: "broken.obj", mimeType: "text/plain",
      buffer: Buffer.from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n"),
    });
    const error = page.locator("#mesh-error");
    await error.waitFor({ state: "visible" });
    const text = await error.textContent();
    assert.match(text, /^422: /);
    assert.match(text, /line 5/);
    assert.match(text, /face 1 uses vertex 7/);
    await shot("error-broken-obj");
    // The mesh shown before is back: the controls still render it.
    assert.match(await page.textContent("#mesh-info"), /96 vertices, 96 faces/);
    const n = await set("#shading", "flat");
    await waitForRenders(n + 1);
    const m = await set("#shading", "smooth");
    await waitForRenders(m + 1);
  });

  it("reads mesh files of other formats: OFF polygons, a binary STL of triangles", async () => {
    // An OFF cube (quads): Catmull-Clark, chosen by the server from its faces.
    const off = "OFF\n8 6 0\n-1 -1 1\n1 -1 1\n-1 1 1\n1 1 1\n-1 1 -1\n1 1 -1\n-1 -1 -1\n" +
                "1 -1 -1\n4 0 1 3 2\n4 2 3 5 4\n4 4 5 7 6\n4 6 7 1 0\n4 1 7 5 3\n4 6 0 2 4\n";
    let renders = await page.evaluate(() => window.limnPage.renders);
    await page.setInputFiles("#upload", { name: "cube.off", mimeType: "application/octet-stream",
                                          buffer: Buffer.from(off) });
    await page.waitForFunction(() => /cube\.off: 8 vertices, 6 faces/.test(
        document.querySelector("#mesh-info").textContent));
    await waitForRenders(renders + 1);
    assert.equal(await page.$eval("#scheme", (el) => el.value), "catmull-clark");
    assert.ok(await inkFraction("#picture") > 0.05, "the OFF cube is not drawn");
    // Loop on its quads is refused: the message names the scheme, and the file, its scheme and
    // its picture stay.
    await page.selectOption("#scheme", "loop");
    await page.locator("#mesh-error").waitFor({ state: "visible" });
    assert.match(await page.textContent("#mesh-error"), /422: .*loop scheme takes triangles only/);
    assert.match(await page.textContent("#mesh-info"), /cube\.off: 8 vertices, 6 faces/);
    assert.equal(await page.$eval("#scheme", (el) => el.value), "catmull-clark");
    renders = await set("#shading", "flat");
    await waitForRenders(renders + 1);
    renders = await set("#shading", "smooth");
    await waitForRenders(renders + 1);

    // A binary STL tetrahedron: every face a triangle, so Loop; its corners welded into 4.
    const corners = [[1, 1, 1], [-1, -1, 1], [-1, 1, -1], [1, -1, -1]];
    const faces = [[0, 1, 3], [0, 2, 1], [0, 3, 2], [1, 2, 3]];
    const stl = Buffer.alloc(84 + 50 * faces.length);
    stl.writeUInt32LE(faces.length, 80);
    faces.forEach((face, f) => {
      face.forEach((v, c) => corners[v].forEach((x, k) => stl.writeFloatLE(x, 84 + 50 * f + 12 + 12 * c + 4 * k)));
    });
    renders = await page.evaluate(() => window.limnPage.renders);
    await page.setInputFiles("#upload", { name: "tetra.stl", mimeType: "model/stl", buffer: stl });
    await page.waitForFunction(() => /tetra\.stl: 4 vertices, 4 faces/.test(
        document.querySelector("#mesh-info").textContent));
    await waitForRenders(renders + 1);
    assert.equal(await page.$eval("#scheme", (el) => el.value), "loop");
    await shot("mesh-file-stl");
  });

  it("shows a transparent background and plays a turntable", async () => {
    let renders = await set("#background", "transparent");
    await waitForRenders(renders + 1);
    const cornerAlpha = await page.$eval("#picture", (img) => {
      const canvas = document.createElement("canvas");
      canvas.width = img.naturalWidth;
      canvas.height = img.naturalHeight;
      const ctx = canvas.getContext("2d");
      ctx.drawImage(img, 0, 0);
      return ctx.getImageData(1, 1, 1, 1).data[3];
    });
    assert.equal(cornerAlpha, 0, "the picture's background is not transparent");
    await shot("transparent-background");
    renders = await set("#background", "white");
    await waitForRenders(renders + 1);

    const turntables = await page.evaluate(() => window.limnPage.turntables);
    await page.selectOption("#turntable-frames", "12");
    await page.click("#turntable");
    await page.waitForFunction((n) => window.limnPage.turntables > n, turntables,
                               { timeout: 120_000 });
    assert.ok(await page.isVisible("#turntable-picture"));
    // It plays: the picture changes from view to view.
    const first = await page.$eval("#turntable-picture", (img) => img.src);
    assert.match(first, /^data:image\/png;base64,/);
    await page.waitForFunction((src) => document.querySelector("#turntable-picture").src !== src,
                               first, { timeout: 10_000 });
    await shot("turntable");
    // The next render puts the picture back.
    renders = await set("#shading", "flat");
    await waitForRenders(renders + 1);
    assert.ok(!(await page.isVisible("#turntable-picture")));
    await set("#shading", "smooth");
  });

  it("refuses a number outside the server's limits at its control, without a request",
     async () => {
    await page.selectOption("#method", "adaptive");
    await waitForRenders((await page.evaluate(() => window.limnPage.renders)) + 1);
    const sent = [];
    const count = (request) => { if (request.url().includes("/v1/")) sent.push(request.url()); };
    page.on("request", count);
    await set("#dicing-rate", 0);  // typed by hand: below limits.minDicingRate
    await page.waitForFunction(() => document.body.classList.contains("stale"));
    assert.match(await page.textContent("#method-error"),
                 /Dicing rate \(px\) must be at least 0\.25 \(the server's limits\.minDicingRate\)/);
    assert.equal(await page.getAttribute("#dicing-rate", "aria-invalid"), "true");
    assert.ok(await page.isVisible("#stale-note"), "no note says the picture is out of date");
    await page.waitForTimeout(300);
    page.off("request", count);
    assert.deepEqual(sent, [], "the page sent a request with a rate of 0");
    await shot("invalid-input");
    const renders = await set("#dicing-rate", 2);
    await waitForRenders(renders + 1);
    assert.ok(!(await page.evaluate(() => document.body.classList.contains("stale"))));
    assert.equal(await page.getAttribute("#dicing-rate", "aria-invalid"), "false");
  });

  it("marks the pictures out of date after a failed request, until one succeeds", async () => {
    // A server error, forced: the next render answers 503 with limn's error body.
    await page.route("**/v1/render", (route) => route.fulfill({
      status: 503, contentType: "application/json",
      body: JSON.stringify({ error: { code: "unavailable", message: "forced by the test" } }),
    }), { times: 1 });
    await set("#shading", "flat");
    await page.waitForFunction(() => document.body.classList.contains("stale"), null,
                               { timeout: 60_000 });
    assert.ok(await page.isVisible("#stale-note"), "no note says the picture is out of date");
    assert.match(await page.textContent("#page-error"), /503: forced by the test/);
    assert.match(await page.textContent("#stale-note"), /out of date: 503: forced by the test/);
    const dimmed = await page.$eval("#picture", (img) => Number(getComputedStyle(img).opacity));
    assert.ok(dimmed < 0.5, `the stale picture's opacity is ${dimmed}`);
    await shot("stale-after-error");
    // The note's retry sends the same request again, which succeeds this time.
    const renders = await page.evaluate(() => window.limnPage.renders);
    await page.click("#retry");
    await waitForRenders(renders + 1);
    assert.ok(!(await page.evaluate(() => document.body.classList.contains("stale"))));
    assert.ok(!(await page.isVisible("#stale-note")));
    const n = await set("#shading", "smooth");
    await waitForRenders(n + 1);
  });

  it("shows the server's warnings under the status line", async () => {
    // The next answer carries a warning, added to the server's real answer.
    await page.route("**/v1/render", async (route) => {
      const response = await route.fetch();
      const answer = await response.json();
      answer.warnings = [...(answer.warnings || []), "a warning added by the test"];
      await route.fulfill({ response, json: answer });
    }, { times: 1 });
    let n = await set("#shading", "flat");
    await waitForRenders(n + 1);
    assert.ok(await page.isVisible("#warnings"));
    assert.match(await page.textContent("#warnings"), /a warning added by the test/);
    n = await set("#shading", "smooth");
    await waitForRenders(n + 1);
    assert.ok(!(await page.isVisible("#warnings")), "the warning outlived its answer");
  });

  it("offers only what works: normal-map shading for coarse and silhouette, factored for " +
     "Catmull–Clark", async () => {
    await page.selectOption("#method", "uniform");
    assert.ok(await page.$eval("#shading option[value=normal-map]", (o) => o.disabled));
    await page.selectOption("#method", "silhouette");
    assert.ok(!(await page.$eval("#shading option[value=normal-map]", (o) => o.disabled)));
    // (Each scheme change uploads the mesh again and renders it: wait for that.)
    let renders = await page.evaluate(() => window.limnPage.renders);
    await page.selectOption("#scheme", "loop");
    await waitForRenders(renders + 1);
    assert.ok(await page.$eval("#engine option[value=factored]", (o) => o.disabled));
    renders = await page.evaluate(() => window.limnPage.renders);
    await page.selectOption("#scheme", "catmull-clark");
    await waitForRenders(renders + 1);
    assert.ok(!(await page.$eval("#engine option[value=factored]", (o) => o.disabled)));
    renders = await page.evaluate(() => window.limnPage.renders);
    await page.selectOption("#method", "uniform");
    await waitForRenders(renders + 1);
  });

  it("compares with the reference: metrics, reference and diff", async () => {
    await page.selectOption("#example", "pawn");
    await page.waitForFunction(() => /Pawn/.test(document.querySelector("#mesh-info").textContent));
    await waitForRenders((await page.evaluate(() => window.limnPage.renders)) + 1);
    await page.selectOption("#method", "uniform");
    const n = await set("#level", 1);
    await waitForRenders(n + 1);
    const m = await set("#compare", true);
    await waitForRenders(m + 1);
    await page.locator("#metrics").waitFor({ state: "visible" });
    const table = await page.textContent("#metrics");
    for (const name of ["outline Hausdorff (px)", "IoU", "PSNR (dB)", "normal mean (deg)",
                        "triangles", "reference"]) {
      assert.ok(table.includes(name), `metrics table lacks ${name}`);
    }
    const answer = await page.evaluate(() => window.limnPage.lastAnswer.metrics);
    assert.ok(answer.silhouette.hausdorffPx > 0, "level 1 should differ from the limit");
    const scale = parseFloat(await page.textContent("#diff-scale"));
    assert.ok(scale > 0 && scale <= 1, `diff scale ${scale}`);
    assert.ok(await inkFraction("#reference") > 0.05, "the reference is blank");
    assert.ok(await inkFraction("#diff") > 0.02, "the diff is blank");
    await shot("compare");
    // Topped by a percentile instead of the largest difference, more of the image is bright.
    const bright = () => page.$eval("#diff", (img) => {
      const canvas = document.createElement("canvas");
      canvas.width = img.naturalWidth;
      canvas.height = img.naturalHeight;
      const ctx = canvas.getContext("2d");
      ctx.drawImage(img, 0, 0);
      const { data } = ctx.getImageData(0, 0, canvas.width, canvas.height);
      let covered = 0, lit = 0;
      for (let i = 0; i < data.length; i += 4) {
        if (data[i + 3] === 0) continue;
        covered += 1;
        lit += data[i] + data[i + 1] + data[i + 2] > 150;
      }
      return lit / covered;
    });
    const linear = await bright();
    await page.selectOption("#diff-top", "90");
    await page.waitForFunction(() => /90th percentile/.test(document.querySelector("#diff-scale").textContent));
    const percentile = await bright();
    console.log(`difference image: ${(100 * linear).toFixed(1)}% of covered pixels bright with ` +
                `the largest on top, ${(100 * percentile).toFixed(1)}% with the 90th percentile`);
    assert.ok(percentile > 1.5 * linear, `${linear} -> ${percentile}`);
    await shot("compare-percentile", page.locator("#panels"));
    await page.selectOption("#diff-top", "largest");
    await page.check("input[value=slider]");
    await shot("compare-slider", page.locator("#approx-panel"));
    assert.ok(await page.isVisible("#slider-divider"), "no divider on the slider");
  });
  it("renders an implicit scene, with its polygoniser and the reference", async () => {
    const options = await page.$$eval("#example option", (os) => os.map((o) => o.value));
    assert.ok(options.includes("scene:metaball_figure") && options.includes("scene:sphere_bite"),
              `no implicit scenes in ${options}`);
    const before = await page.evaluate(() => window.limnPage.renders);
    await page.selectOption("#example", "scene:sphere_bite");  // the quickest reference
    await waitForRenders(before + 1);
    assert.ok(await page.isVisible("#polygonizer"), "the polygoniser controls are hidden");
    assert.ok(!(await page.isVisible("#method")), "the mesh method control still shows");
    assert.match(await page.textContent("#mesh-info"), /implicit field of 2 primitives/);
    assert.match(await page.textContent("#stats"), /closed · 2 primitives/);
    assert.ok(await inkFraction("#picture") > 0.02, "the scene's picture is blank");
    const answer = await page.evaluate(() => window.limnPage.lastAnswer);
    assert.equal(answer.stats.implicit.polygonizer, "marching-cubes");
    if (await page.$eval("#compare", (el) => el.checked)) {
      assert.ok(answer.metrics.silhouette.hausdorffPx <= 1.0,
                `${answer.metrics.silhouette.hausdorffPx} px from the reference`);
    }
    const marched = await triangles();
    const n = await set("#polygonizer", "octree");
    await waitForRenders(n + 1);
    const octree = await page.evaluate(() => window.limnPage.lastAnswer.stats);
    assert.equal(octree.implicit.polygonizer, "octree");
    assert.ok(octree.closed, "the octree mesh is not closed");
    assert.notEqual(await triangles(), marched, "the polygoniser did not change the mesh");
    await shot("implicit-scene");
    // Back to a mesh: its controls return.
    const m = await page.evaluate(() => window.limnPage.renders);
    await page.selectOption("#example", "cube");
    await waitForRenders(m + 1);
    assert.ok(await page.isVisible("#method"), "the method control did not come back");
    assert.ok(!(await page.isVisible("#polygonizer")), "the polygoniser controls stayed");
  });

  it("draws feature-adaptive patches, and colours them by level on request", async () => {
    let n = await set("#compare", false);
    await waitForRenders(n + 1);
    n = await set("#method", "patches");
    await waitForRenders(n + 1);
    assert.ok(await page.isVisible("#isolation"), "the patch controls are hidden");
    const stats = await page.evaluate(() => window.limnPage.lastAnswer.stats);
    assert.ok(stats.patchTable && stats.patchTable.patches > 0, "no patch table in the answer");
    assert.equal(stats.patchTable.isolation, 6);
    await keepPixels("#picture", "patchesShaded");
    n = await set("#show-patches", true);
    await waitForRenders(n + 1);
    await keepPixels("#picture", "patchesByLevel");
    const changed = await differingFraction("patchesShaded", "patchesByLevel");
    assert.ok(changed > 0.05, `the patch colours changed only ${(100 * changed).toFixed(2)}%`);
    await shot("patches-by-level", page.locator("#view"));
    // Compared with the reference, the patch colours stay and the reference shows its colour
    // (it has no patches: the page asks for colour beside them).
    n = await set("#compare", true);
    await waitForRenders(n + 1);
    assert.ok(!(await page.isVisible("#page-error")), await page.textContent("#page-error"));
    assert.ok(await inkFraction("#reference") > 0.05, "the reference is blank");
    n = await set("#compare", false);
    await waitForRenders(n + 1);
  });

  it("displaces the surface, and the reference with it", async () => {
    let n = await set("#show-patches", false);
    await waitForRenders(n + 1);
    assert.ok(await page.isVisible("#displacement"), "the displacement control is hidden");
    await keepPixels("#picture", "undisplaced");
    n = await set("#displacement", "bumps");
    await waitForRenders(n + 1);
    await keepPixels("#picture", "bumps");
    const changed = await differingFraction("undisplaced", "bumps");
    assert.ok(changed > 0.05, `the bumps changed only ${(100 * changed).toFixed(2)}% of the picture`);
    // Measured against the displaced reference: still within a pixel.
    n = await set("#compare", true);
    await waitForRenders(n + 1);
    const answer = await page.evaluate(() => window.limnPage.lastAnswer);
    assert.ok(answer.metrics.silhouette.hausdorffPx <= 1.0,
              `displaced patches ${answer.metrics.silhouette.hausdorffPx} px off the displaced reference`);
    await shot("displaced-patches", page.locator("#view"));
    // A method that does not draw it hides the control and sends none (with it, uniform is a
    // 400 and no render would count).
    n = await set("#compare", false);
    await waitForRenders(n + 1);
    n = await set("#method", "uniform");
    await waitForRenders(n + 1);
    assert.ok(!(await page.isVisible("#displacement")), "the displacement control stayed");
    await set("#displacement", "none");
  });

  // ------------------------------------------------------------ layout, touch, honest controls

  // Every picture shown, with its box, its panel's box and its pixel size.
  const pictureBoxes = (p) => p.$$eval("#picture, #reference, #diff", (imgs) => imgs
      .filter((img) => img.offsetParent !== null && getComputedStyle(img).display !== "none")
      .map((img) => {
        const r = img.getBoundingClientRect();
        const panel = img.closest("figure").getBoundingClientRect();
        return { id: img.id, left: r.left, right: r.right, top: r.top, bottom: r.bottom,
                 width: r.width, panel: panel.width, natural: img.naturalWidth,
                 naturalHeight: img.naturalHeight, height: r.height };
      }));

  for (const [width, height] of [[390, 844], [1024, 768], [1920, 1080]]) {
    it(`fits a ${width}x${height} window: nothing off screen, pictures as wide as their panels`,
       async () => {
      const other = await browser.newPage({ viewport: { width, height } });
      other.on("pageerror", (error) => console.log(`page error: ${error.message}`));
      for (const compare of [false, true]) {
        await other.goto(`${baseUrl}/?example=cube&level=1${compare ? "&compare=1" : ""}`);
        await other.waitForFunction(() => window.limnPage.renders >= 1 && !window.limnPage.busy,
                                    null, { timeout: 120_000 });
        const shown = await other.evaluate(() => ({
          scrollWidth: document.documentElement.scrollWidth, dpr: devicePixelRatio,
        }));
        assert.ok(shown.scrollWidth <= width, `the page is ${shown.scrollWidth} px wide`);
        const boxes = await pictureBoxes(other);
        assert.equal(boxes.length, compare ? 3 : 1, JSON.stringify(boxes));
        for (const b of boxes) {
          assert.ok(b.left >= 0 && b.right <= width + 0.5, `${b.id} off screen: ${JSON.stringify(b)}`);
          assert.ok(b.width >= 0.8 * b.panel, `${b.id} is ${b.width} px of a ${b.panel} px panel`);
          // A phone scrolls to the compare panels below the picture; a desktop shows them all.
          if (width > 800 || b.id === "picture") {
            assert.ok(b.top >= 0 && b.bottom <= height, `${b.id} below the fold: ${JSON.stringify(b)}`);
          }
          // Requested at the size it is shown, in device pixels.
          assert.ok(Math.abs(b.natural - b.width * shown.dpr) <= 1,
                    `${b.id}: ${b.natural} px drawn for ${b.width} px shown`);
        }
        if (!compare) {  // the picture takes the width beside the controls (all of it on a phone)
          const room = width > 800 ? width - 290 - 36 : width - 24;
          assert.ok(boxes[0].width >= 0.95 * room, `the picture is ${boxes[0].width} px of ${room}`);
        }
        await other.screenshot({ path: path.join(artifacts, `layout-${width}x${height}${compare ? "-compare" : ""}.png`) });
      }
      if (width <= 800) {
        // The controls are a drawer, opened from the status line.
        assert.ok(!(await other.isVisible("#method")), "the controls cover the picture");
        await other.click("#open-controls");
        await other.locator("#method").waitFor({ state: "visible" });
        await other.waitForTimeout(400);  // the drawer slides in
        const box = await other.locator("#controls").boundingBox();
        assert.ok(box.x >= -0.5 && box.x + box.width <= width + 0.5, JSON.stringify(box));
        await other.screenshot({ path: path.join(artifacts, `layout-${width}x${height}-drawer.png`) });
        await other.click("#close-controls");
        await other.locator("#method").waitFor({ state: "hidden" });
      } else {
        // During a drag the reference and the difference (the camera before) are dimmed.
        const box = await other.locator("#view").boundingBox();
        await other.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
        await other.mouse.down();
        await other.mouse.move(box.x + box.width / 2 + 40, box.y + box.height / 2);
        const opacity = await other.$eval("#reference", (img) => Number(getComputedStyle(img).opacity));
        assert.ok(await other.isVisible("#reference-panel .drag-note"));
        await other.mouse.up();
        assert.ok(opacity < 0.5, `the reference's opacity during a drag is ${opacity}`);
        // Turned into a phone: laid out again, and a picture of the new size is asked for.
        await other.waitForFunction(() => !window.limnPage.busy);
        const n = await other.evaluate(() => window.limnPage.renders);
        await other.setViewportSize({ width: 390, height: 844 });
        await other.waitForFunction((k) => window.limnPage.renders > k && !window.limnPage.busy, n,
                                    { timeout: 60_000 });
        const boxes = await pictureBoxes(other);
        for (const b of boxes) {
          assert.ok(b.right <= 390.5 && Math.abs(b.natural - b.width) <= 1, JSON.stringify(b));
        }
      }
      await other.close();
    });
  }

  it("orbits with one finger and zooms with two (touch pointer events)", async () => {
    const other = await browser.newPage({ viewport: { width: 390, height: 844 }, hasTouch: true,
                                          isMobile: true });
    await other.goto(`${baseUrl}/?example=cube`);
    await other.waitForFunction(() => window.limnPage.renders >= 1 && !window.limnPage.busy);
    const before = await other.$eval("#view", (el) => ({ ...el.dataset }));
    // Touch pointers as a browser sends them: pointerdown, pointermove..., pointerup.
    const touch = (type, id, x, y) => other.$eval("#view", (view, [type, id, x, y]) => {
      const r = view.getBoundingClientRect();
      view.dispatchEvent(new PointerEvent(type, { pointerId: id, pointerType: "touch", isPrimary: id === 1,
                                                  clientX: r.left + x, clientY: r.top + y, bubbles: true }));
    }, [type, id, x, y]);
    await touch("pointerdown", 1, 100, 150);
    for (let i = 1; i <= 10; i++) await touch("pointermove", 1, 100 + 8 * i, 150);
    await touch("pointerup", 1, 180, 150);
    await other.waitForFunction(() => window.limnPage.renders >= 2 && !window.limnPage.busy);
    const orbited = await other.$eval("#view", (el) => ({ ...el.dataset }));
    assert.ok(Math.abs(Number(orbited.azimuth) - Number(before.azimuth)) >= 30,
              `azimuth ${before.azimuth} -> ${orbited.azimuth}`);
    // Two fingers spreading from 100 to 200 px apart: half the distance.
    await touch("pointerdown", 1, 125, 150);
    await touch("pointerdown", 2, 225, 150);
    for (let i = 1; i <= 10; i++) {
      await touch("pointermove", 1, 125 - 5 * i, 150);
      await touch("pointermove", 2, 225 + 5 * i, 150);
    }
    await touch("pointerup", 1, 75, 150);
    await touch("pointerup", 2, 275, 150);
    await other.waitForFunction(() => window.limnPage.renders >= 3 && !window.limnPage.busy);
    const pinched = await other.$eval("#view", (el) => ({ ...el.dataset }));
    const framing = 1.05 / Math.sin((35 * Math.PI) / 360);
    assert.ok(Math.abs(Number(pinched.distance) - framing / 2) < 0.05,
              `distance after the pinch: ${pinched.distance} (default ${framing.toFixed(3)})`);
    assert.equal(pinched.azimuth, orbited.azimuth, "the pinch turned the view");
    await other.close();
  });

  it("disables what cannot apply, and says why", async () => {
    let n = await set("#draw-cage", true);
    await waitForRenders(n + 1);
    assert.ok(await page.$eval("#draw-wireframe", (el) => el.disabled));
    assert.match(await page.textContent("#draw-wireframe-why"), /either the control cage or the wireframe/);
    assert.ok(await page.isVisible("#draw-wireframe-why"));
    n = await set("#draw-surface", false);
    await waitForRenders(n + 1);
    assert.match(await page.textContent("#draw-wireframe-why"), /switch the surface on/);
    n = await set("#draw-surface", true);
    await waitForRenders(n + 1);
    n = await set("#draw-cage", false);
    await waitForRenders(n + 1);
    assert.ok(!(await page.$eval("#draw-wireframe", (el) => el.disabled)));
    assert.ok(!(await page.isVisible("#draw-wireframe-why")));
    // The limit method is the reference: nothing to compare, no triangles to export.
    n = await set("#method", "limit");
    await waitForRenders(n + 1);
    assert.ok(await page.$eval("#compare", (el) => el.disabled));
    assert.match(await page.textContent("#compare-why"), /limit method is the exact reference/);
    assert.ok(await page.$eval("[data-mesh-format=glb]", (el) => el.disabled));
    assert.match(await page.textContent("#export-why"), /ray cast/);
    await shot("disabled-with-reason");
    n = await set("#method", "uniform");
    await waitForRenders(n + 1);
    assert.ok(!(await page.$eval("#compare", (el) => el.disabled)));
  });

  it("takes keys for the level, wireframe, shading, views and reset, listed in the page", async () => {
    const keys = await page.textContent("#shortcuts");
    for (const word of ["wireframe", "shading", "reset", "iteration", "orthographic"]) {
      assert.ok(keys.includes(word), `the shortcuts do not mention ${word}`);
    }
    await page.locator("#view").focus();
    const level = Number(await page.$eval("#level", (el) => el.value));
    let n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("+");
    await waitForRenders(n + 1);
    assert.equal(Number(await page.$eval("#level", (el) => el.value)), Math.min(6, level + 1));
    n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("-");
    await waitForRenders(n + 1);
    assert.equal(Number(await page.$eval("#level", (el) => el.value)), level);
    n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("w");
    await waitForRenders(n + 1);
    assert.ok(await page.$eval("#draw-wireframe", (el) => el.checked));
    assert.ok(await page.evaluate(() => "wireframe" in window.limnPage.lastAnswer.images));
    n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("w");
    await waitForRenders(n + 1);
    n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("s");
    await waitForRenders(n + 1);
    assert.equal(await page.$eval("#shading", (el) => el.value), "flat");
    n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("s");
    await waitForRenders(n + 1);
    n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("3");  // top
    await waitForRenders(n + 1);
    assert.equal(await page.$eval("#view", (el) => el.dataset.elevation), "90.0");
    n = await page.evaluate(() => window.limnPage.renders);
    await page.keyboard.press("r");
    await waitForRenders(n + 1);
    assert.notEqual(await page.$eval("#view", (el) => el.dataset.elevation), "90.0");
  });

  it("keeps its state in the address: the shared URL reopens mesh, method, settings and camera",
     async () => {
    let n = await set("#level", 1);
    await waitForRenders(n + 1);
    n = await page.evaluate(() => window.limnPage.renders);
    await page.click("[data-view=side]");
    await waitForRenders(n + 1);
    n = await set("#orthographic", true);
    await waitForRenders(n + 1);
    n = await page.evaluate(() => window.limnPage.renders);
    await page.mouse.move(0, 0);
    const box = await page.locator("#view").boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.wheel(0, -200);  // zoom in
    await waitForRenders(n + 1);
    n = await set("#shading", "flat");
    await waitForRenders(n + 1);
    // The local view draws the same orthographic, zoomed camera as the server.
    await page.waitForFunction(() => window.limnPage.localReady, null, { timeout: 60_000 });
    await keepPixels("#picture", "orthoServer");
    await keepLocalSnapshot("orthoLocal");
    await page.$eval("#gl-canvas", (c) => { c.hidden = true; });
    const disagree = await differingFraction("orthoServer", "orthoLocal");
    console.log(`orthographic local view vs server picture: ${(100 * disagree).toFixed(2)}% differ`);
    assert.ok(disagree < 0.03, `${(100 * disagree).toFixed(2)}% of the pixels differ`);
    await page.click("#copy-link");
    const url = await page.evaluate(() => location.href);
    assert.match(url, /example=\w+/);
    const want = await page.evaluate(() => ({
      camera: window.limnPage.lastAnswer.camera, level: document.querySelector("#level").value,
      shading: document.querySelector("#shading").value,
      ortho: document.querySelector("#orthographic").checked,
      method: document.querySelector("#method").value,
    }));
    assert.equal(want.camera.projection, "orthographic");
    const other = await browser.newPage({ viewport: { width: 1240, height: 800 } });
    await other.goto(url);
    await other.waitForFunction(() => window.limnPage.renders >= 1 && !window.limnPage.busy);
    const got = await other.evaluate(() => ({
      camera: window.limnPage.lastAnswer.camera, level: document.querySelector("#level").value,
      shading: document.querySelector("#shading").value,
      ortho: document.querySelector("#orthographic").checked,
      method: document.querySelector("#method").value,
    }));
    for (const key of ["level", "shading", "ortho", "method"]) assert.equal(got[key], want[key], key);
    assert.equal(got.camera.projection, "orthographic");
    assert.ok(Math.abs(got.camera.orthoHeight - want.camera.orthoHeight) < 1e-3 * want.camera.orthoHeight,
              `orthoHeight ${got.camera.orthoHeight} vs ${want.camera.orthoHeight}`);
    for (let k = 0; k < 3; k++) {
      assert.ok(Math.abs(got.camera.eye[k] - want.camera.eye[k]) < 1e-2, `eye ${got.camera.eye} vs ${want.camera.eye}`);
    }
    await other.close();
    // An uploaded mesh is named by its id on the server.
    const off = "OFF\n4 4 0\n1 1 1\n-1 -1 1\n-1 1 -1\n1 -1 -1\n3 0 1 3\n3 0 2 1\n3 0 3 2\n3 1 2 3\n";
    n = await page.evaluate(() => window.limnPage.renders);
    await page.setInputFiles("#upload", { name: "tetra.off", mimeType: "application/octet-stream",
                                          buffer: Buffer.from(off) });
    await waitForRenders(n + 1);
    const uploaded = await page.evaluate(() => location.href);
    assert.match(uploaded, /mesh=[0-9a-f]{32}/);
    const third = await browser.newPage({ viewport: { width: 1240, height: 800 } });
    await third.goto(uploaded);
    await third.waitForFunction(() => window.limnPage.renders >= 1 && !window.limnPage.busy);
    assert.equal(await third.evaluate(() => window.limnPage.lastAnswer.stats.controlFaces), 4);
    assert.match(await third.textContent("#mesh-info"), /tetra\.off/);
    await third.close();
    n = await set("#orthographic", false);
    await waitForRenders(n + 1);
    n = await page.evaluate(() => window.limnPage.renders);
    await page.selectOption("#example", "cube");
    await waitForRenders(n + 1);
  });

  it("downloads the pictures, the metrics and the approximation as valid files", async () => {
    const { readFileSync } = await import("node:fs");
    const fetchDownload = async (selector) => {
      const [download] = await Promise.all([page.waitForEvent("download", { timeout: 60_000 }),
                                            page.click(selector)]);
      return { name: download.suggestedFilename(), bytes: readFileSync(await download.path()) };
    };
    const n = await set("#compare", true);
    await waitForRenders(n + 1);
    const png = await fetchDownload("#download-png");
    assert.match(png.name, /^limn-[\w.-]+-uniform-compare\.png$/);
    assert.deepEqual([...png.bytes.subarray(0, 8)], [137, 80, 78, 71, 13, 10, 26, 10]);
    // Three pictures side by side.
    const size = await page.evaluate(() => window.limnPage.requestSize);
    assert.equal(png.bytes.readUInt32BE(16), 3 * size.width);
    const json = JSON.parse((await fetchDownload("#download-json")).bytes.toString());
    assert.ok(json.metrics.silhouette.iou > 0 && json.metrics.silhouette.iou <= 1,
              JSON.stringify(json.metrics));
    assert.equal(json.method, "uniform");
    const csv = (await fetchDownload("#download-csv")).bytes.toString().trim().split("\n");
    assert.equal(csv[0], "key,value");
    const iou = csv.find((line) => line.startsWith("metrics.silhouette.iou,"));
    assert.ok(iou && Number(iou.split(",")[1]) === json.metrics.silhouette.iou, iou);
    const glb = await fetchDownload("[data-mesh-format=glb]");
    assert.equal(glb.bytes.subarray(0, 4).toString(), "glTF");
    assert.equal(glb.bytes.readUInt32LE(4), 2);
    assert.equal(glb.bytes.readUInt32LE(8), glb.bytes.length);
    const ply = await fetchDownload("[data-mesh-format=ply]");
    assert.match(ply.bytes.subarray(0, 40).toString("latin1"), /^ply\n/);
    const obj = (await fetchDownload("[data-mesh-format=obj]")).bytes.toString();
    const triangles = obj.split("\n").filter((line) => line.startsWith("f ")).length;
    assert.equal(triangles, json.stats.triangles);
    const m = await set("#compare", false);
    await waitForRenders(m + 1);
  });
});
