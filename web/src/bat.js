// The bat: the form that describes it (as the API's `bat` object, docs/api.md
// "The bat"), the scene around it, and its drawing to scale (outline, hollow
// shell, bored fill) with the sweet-spot markers.
import { readFields, readValue } from './form.js';

const SVG = 'http://www.w3.org/2000/svg';

/**
 * The bat editor: a preset (its profile from GET /v1/presets) or a
 * three-segment shape, a material, a wall and a fill; plus the scene.
 */
export class BatForm {
  /** `form` is the bat <form>; `catalogue` has `presets` and `materials` (name -> API object). */
  constructor(form, catalogue) {
    this.form = form;
    this.catalogue = catalogue;
    this.populate();
    for (const select of form.querySelectorAll('select')) select.dataset.default = select.value;
    this.syncShape();
  }

  /** Fills the preset, material and ball lists from the API's catalogues. */
  populate() {
    const preset = this.form.elements.preset;
    for (const p of this.catalogue.presets.values()) {
      preset.append(new Option(p.name, p.name));
    }
    // A real bat at game conditions (issue 37); the paper's bat is one choice away.
    preset.value = ['wood-34-ash', 'paper-wood'].find((name) => this.catalogue.presets.has(name)) ||
      preset.options[1]?.value || '';
    const ball = this.form.elements.ball_preset;
    for (const b of this.catalogue.balls.values()) ball.append(new Option(b.name, b.name));
    if (this.catalogue.balls.has('mlb')) ball.value = 'mlb';
    const material = this.form.elements.material;
    const fill = this.form.elements.fill_material;
    for (const m of this.catalogue.materials.values()) {
      material.append(new Option(m.name, m.name));
      fill.append(new Option(m.name, m.name));
    }
    fill.append(new Option('empty (a hollow bore)', 'empty'));
  }

  /** Enables the inputs the chosen shape uses, and shows the preset's description. */
  syncShape() {
    const { preset, shape } = this.form.elements;
    const presetOption = shape.querySelector('option[value="preset"]');
    presetOption.disabled = !preset.value;
    if (!preset.value) shape.value = 'three_segment';
    const three = shape.value === 'three_segment';
    for (const input of this.form.querySelectorAll('[data-field^="bat.three_segment."]')) {
      input.disabled = !three;
    }
    const fillOn = !['', 'none'].includes(this.form.elements.fill_material.value);
    for (const input of this.form.querySelectorAll('input[data-field^="bat.fill."]')) input.disabled = !fillOn;
    const about = this.form.querySelector('#preset-about');
    const p = this.catalogue.presets.get(preset.value);
    about.textContent = p ? p.description : 'No preset: the three-segment shape below, in the material chosen.';
  }

  /** The chosen preset's API object, or undefined. */
  preset() {
    return this.catalogue.presets.get(this.form.elements.preset.value);
  }

  /** The `bat` object of a request, exactly as the inputs say. */
  request() {
    const e = this.form.elements;
    const bat = {};
    if (e.preset.value) bat.preset = e.preset.value;
    if (e.shape.value === 'three_segment') {
      bat.three_segment = readFields(this.form, 'bat.three_segment.');
    }
    if (e.material.value) bat.material = e.material.value;
    const wall = readValue(e.wall_thickness_m);
    if (wall !== undefined) bat[e.wall_thickness_m.dataset.field.slice('bat.'.length)] = wall;
    if (e.fill_material.value === 'none') {
      bat.fill = null;
    } else if (e.fill_material.value) {
      bat.fill = { material: e.fill_material.value, ...readFields(this.form, 'bat.fill.') };
    }
    return bat;
  }

  /** The scene fields of a request (ball, swing, cor): only those given. */
  scene() {
    const scene = {};
    const ball = this.form.elements.ball_preset.value;
    if (ball) scene.ball = { preset: ball };
    for (const prefix of ['ball.', 'swing.', 'contact.', 'cor']) readFields(this.form, prefix, true, scene);
    return scene;
  }

  /**
   * What to draw for the bat the inputs describe: the knots (a preset's from
   * GET /v1/presets; a three-segment bat's four knots by the form's
   * definition: r1 on [0, x1], linear to r2 at x2, r2 to L), the wall, the
   * fill and the material's name. Null when the inputs do not describe one.
   */
  outline(bat = this.request()) {
    return outlineOf(bat, this.catalogue);
  }
}

/** The drawing data of a request's `bat` (see BatForm.outline); null if incomplete. */
export function outlineOf(bat, catalogue) {
  const preset = bat.preset ? catalogue.presets.get(bat.preset) : undefined;
  let knots = null;
  if (bat.profile && Array.isArray(bat.profile.knots)) {
    // A profile in the request's form: knots in metres (x_m, radius_m) or, when the request
    // gave its variables in inches, in inches (x_in, diameter_in): drawn at their size.
    knots = bat.profile.knots.map((k) => ({ x_m: lengthM(k, 'x'), radius_m: radiusM(k, '') }));
    if (!knots.every((k) => Number.isFinite(k.x_m) && Number.isFinite(k.radius_m))) return null;
  } else if (bat.three_segment) {
    const s = {
      length_m: lengthM(bat.three_segment, 'length'),
      handle_radius_m: radiusM(bat.three_segment, 'handle'),
      barrel_radius_m: radiusM(bat.three_segment, 'barrel'),
      taper_start_m: lengthM(bat.three_segment, 'taper_start'),
      taper_end_m: lengthM(bat.three_segment, 'taper_end'),
    };
    const values = [s.length_m, s.handle_radius_m, s.barrel_radius_m, s.taper_start_m, s.taper_end_m];
    if (!values.every((v) => typeof v === 'number' && Number.isFinite(v))) return null;
    knots = [
      { x_m: 0, radius_m: s.handle_radius_m },
      { x_m: s.taper_start_m, radius_m: s.handle_radius_m },
      { x_m: s.taper_end_m, radius_m: s.barrel_radius_m },
      { x_m: s.length_m, radius_m: s.barrel_radius_m },
    ];
  } else if (preset) {
    knots = preset.bat.profile.knots;
  }
  if (!knots) return null;
  const wall =
    'wall_thickness_m' in bat || 'wall_thickness_in' in bat
      ? lengthM(bat, 'wall_thickness')
      : preset?.bat.wall_thickness_m || 0;
  let fill = 'fill' in bat ? bat.fill : preset?.bat.fill || null;
  if (fill) fill = { ...fill, diameter_m: lengthM(fill, 'diameter'), depth_m: lengthM(fill, 'depth') };
  if (fill && !(Number.isFinite(fill.diameter_m) && Number.isFinite(fill.depth_m))) fill = null;
  let material = bat.material ?? preset?.bat.material ?? 'paper-wood';
  if (typeof material === 'object') material = material.name || 'custom';
  let fillMaterial = fill?.material ?? null;
  if (fillMaterial && typeof fillMaterial === 'object') fillMaterial = fillMaterial.name || 'custom';
  return {
    knots,
    wall_m: typeof wall === 'number' ? wall : 0,
    fill: fill ? { diameter_m: fill.diameter_m, depth_m: fill.depth_m, material: fillMaterial } : null,
    material,
  };
}

/** Drawing units per inch: a length given in inches is drawn at its size (pixels only). */
const DRAWN_M_PER_IN = 0.0254;

/** `obj[stem_m]`, or `obj[stem_in]` at its drawn size; undefined when neither is a number. */
function lengthM(obj, stem) {
  if (typeof obj[`${stem}_m`] === 'number') return obj[`${stem}_m`];
  if (typeof obj[`${stem}_in`] === 'number') return obj[`${stem}_in`] * DRAWN_M_PER_IN;
  return undefined;
}

/** A radius given as `stem_radius_m`, or as a diameter `stem_diameter_{m,in}`, for the drawing. */
function radiusM(obj, stem) {
  const prefix = stem ? `${stem}_` : '';
  const radius = lengthM(obj, `${prefix}radius`);
  if (radius !== undefined) return radius;
  const diameter = lengthM(obj, `${prefix}diameter`);
  return diameter === undefined ? undefined : diameter / 2;
}

function svgEl(tag, attrs = {}) {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attrs)) node.setAttribute(key, String(value));
  return node;
}

function materialClass(name) {
  if (/alumin|alloy|steel|titan/i.test(name || '')) return 'metal';
  if (/cork/i.test(name || '')) return 'cork';
  if (/rubber/i.test(name || '')) return 'rubber';
  if (name === 'empty') return 'empty';
  return 'wood';
}

// The outline's points in mm, top edge knob to tip then bottom edge back.
function outlinePath(knots, inset = 0) {
  const top = knots.map((k) => `${(k.x_m * 1000).toFixed(3)},${(-(k.radius_m - inset) * 1000).toFixed(3)}`);
  const bottom = [...knots]
    .reverse()
    .map((k) => `${(k.x_m * 1000).toFixed(3)},${((k.radius_m - inset) * 1000).toFixed(3)}`);
  return `M${top.join('L')}L${bottom.join('L')}Z`;
}

/**
 * Draws bats to scale into `svg` (1 unit = 1 mm, the same scale along and
 * across): each of `bats` is an outline (outlineOf) with a `role` ("main",
 * "original" drawn as a dashed outline only, or "optimised"). `marks` are
 * {key, label, position_m} vertical lines; `zone` a {from_m, to_m} band.
 */
export function drawBat(svg, bats, { marks = [], zone = null, axis = true, axisUnit = 'm' } = {}) {
  svg.replaceChildren();
  const shown = bats.filter(Boolean);
  if (!shown.length) return;
  const length = Math.max(...shown.map((b) => b.knots[b.knots.length - 1].x_m)) * 1000;
  const radius = Math.max(...shown.flatMap((b) => b.knots.map((k) => k.radius_m))) * 1000;
  const pad = 10;
  const top = -radius - (marks.length ? 36 : pad);
  const bottom = radius + (axis ? 40 : pad);
  svg.setAttribute('viewBox', `${-pad} ${top} ${length + 2 * pad} ${bottom - top}`);
  svg.dataset.lengthM = String(length / 1000);

  if (zone && Number.isFinite(zone.from_m) && Number.isFinite(zone.to_m)) {
    svg.append(
      svgEl('rect', {
        class: 'zone',
        x: zone.from_m * 1000,
        y: -radius - 6,
        width: Math.max(0, (zone.to_m - zone.from_m) * 1000),
        height: 2 * radius + 12,
      }),
    );
  }
  for (const bat of shown) {
    const role = bat.role || 'main';
    const group = svgEl('g', { class: `bat ${role} ${materialClass(bat.material)}` });
    group.dataset.material = bat.material;
    group.append(svgEl('path', { class: 'body', d: outlinePath(bat.knots) }));
    const minRadius = Math.min(...bat.knots.map((k) => k.radius_m));
    if (bat.wall_m > 0 && bat.wall_m < minRadius) {
      // The hollow inside the shell (inner radius = outer - wall).
      group.append(svgEl('path', { class: 'hollow', d: outlinePath(bat.knots, bat.wall_m) }));
      group.dataset.wallM = String(bat.wall_m);
    }
    if (bat.fill && bat.fill.depth_m > 0 && bat.fill.diameter_m > 0) {
      const end = bat.knots[bat.knots.length - 1].x_m * 1000;
      const depth = Math.min(bat.fill.depth_m * 1000, end);
      const r = (bat.fill.diameter_m * 1000) / 2;
      group.append(
        svgEl('rect', {
          class: `fill ${materialClass(bat.fill.material)}`,
          x: end - depth,
          y: -r,
          width: depth,
          height: 2 * r,
        }),
      );
      group.dataset.fillDepthM = String(bat.fill.depth_m);
    }
    group.append(svgEl('path', { class: 'edge', d: outlinePath(bat.knots) }));
    svg.append(group);
  }
  if (axis) {
    const y = radius + 8;
    const g = svgEl('g', { class: 'axis' });
    g.append(svgEl('line', { x1: 0, x2: length, y1: y, y2: y }));
    // Ticks every 0.1 m, or every 4 in (101.6 drawing units: the scale of the drawing only).
    const inches = axisUnit === 'in';
    const step = inches ? 4 * 25.4 : 100;
    for (let i = 0; i * step <= length + 1e-6; ++i) {
      const mm = i * step;
      g.append(svgEl('line', { x1: mm, x2: mm, y1: y, y2: y + 5 }));
      const label = svgEl('text', { x: mm, y: y + 19, 'text-anchor': 'middle' });
      label.textContent = inches ? String(4 * i) : (i / 10).toFixed(1);
      g.append(label);
    }
    const unit = svgEl('text', { x: length, y: y + 32, 'text-anchor': 'end' });
    unit.textContent = `${inches ? 'in' : 'm'} from the knob`;
    g.append(unit);
    svg.append(g);
  }
  marks.forEach((mark, i) => {
    if (!Number.isFinite(mark.position_m)) return;
    const x = mark.position_m * 1000;
    const g = svgEl('g', { class: `mark ${mark.key}` });
    g.dataset.marker = mark.key;
    g.dataset.positionM = String(mark.position_m);
    g.append(svgEl('line', { x1: x, x2: x, y1: -radius - 6, y2: radius + 6 }));
    const label = svgEl('text', { x, y: -radius - 9 - (i % 3) * 9, 'text-anchor': 'middle' });
    label.textContent = mark.short || mark.label;
    const title = svgEl('title');
    const shown = mark.at ?? mark.position_m;
    title.textContent = `${mark.label}: ${shown.toFixed(axisUnit === 'in' ? 2 : 4)} ${axisUnit} from the knob`;
    g.append(title);
    g.append(label);
    svg.append(g);
  });
}
