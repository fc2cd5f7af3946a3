// How big each picture is: pure functions of the space there is, used by app.js's
// layoutPanels (the panels' CSS size) and requestSize (the pixels asked of the server).

const PANEL_GAP = 14, CAPTION = 22, SLIDER = 26;

// The size {w, h} in CSS pixels of each of `panels` pictures (1 alone; 2 for the slider layout,
// the approximation with its slider and the difference; 3 side by side) in a space `width` wide
// with `height` left below its top. Alone: the whole width, as tall as there is room, never
// taller than wide (the camera's field of view is vertical). Several: squares, in the number of
// columns that leaves them largest, all on screen; below 600 px each takes the whole width,
// stacked (the page scrolls).
export function panelSize(width, height, panels) {
  const extra = CAPTION + (panels === 2 ? SLIDER : 0);
  let w, h;
  if (panels === 1) {
    w = width;
    h = Math.min(width, Math.max(height - extra, Math.min(width, 240)));
  } else if (width < 600) {
    w = h = width;
  } else {
    let best = 0;
    for (let columns = 1; columns <= panels; columns++) {
      const rows = Math.ceil(panels / columns);
      const side = Math.min((width - (columns - 1) * PANEL_GAP) / columns,
                            (height - rows * extra - (rows - 1) * PANEL_GAP) / rows);
      best = Math.max(best, side);
    }
    w = h = Math.max(best, Math.min(width, 200));
  }
  return { w: Math.max(64, Math.floor(w)), h: Math.max(64, Math.floor(h)) };
}

// The picture's size in pixels for a panel of `size` CSS pixels (its 1 px border left out):
// "auto", the panel in device pixels (`dpr`) within `cap` a side; else the chosen number of
// pixels along the longer side, the panel's shape kept.
export function pixelSize(size, choice, dpr, cap) {
  let w = size.w - 2, h = size.h - 2;
  if (choice === "auto") {
    w *= dpr;
    h *= dpr;
  } else {
    cap = Number(choice);
    const fit = cap / Math.max(w, h);
    w *= fit;
    h *= fit;
  }
  const scale = Math.min(1, cap / Math.max(w, h));
  return { width: Math.max(16, Math.round(w * scale)), height: Math.max(16, Math.round(h * scale)) };
}
