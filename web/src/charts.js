// Charts (uPlot): the exit-speed curve with its markers, the mode shapes and
// the variants' curves. Markers are DOM elements over the plot (positioned
// from the API's values), so that they can be read, tested and hovered.
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';

/** Series colours, also used by the variants' table. */
export const PALETTE = ['#1f5fa8', '#c2410c', '#15803d', '#7e22ce', '#a16207', '#be123c', '#0f766e'];

const HEIGHT = 260;

function widthOf(container) {
  return Math.max(280, Math.floor(container.getBoundingClientRect().width || 600));
}

/** A uPlot chart that follows its container's width. */
class Chart {
  constructor(container, { xLabel = 'position from the knob (m)', yLabel, onDraw }) {
    this.container = container;
    this.xLabel = xLabel;
    this.yLabel = yLabel;
    this.onDraw = onDraw;
    this.plot = null;
    this.seriesKey = '';
    new ResizeObserver(() => {
      if (this.plot) this.plot.setSize({ width: widthOf(container), height: HEIGHT });
    }).observe(container);
  }

  /** Shows `data` ([xs, ys1, ys2, ...]) with `series` ([{label, stroke, dash}]). */
  show(data, series) {
    this.data = data;
    this.seriesLabels = series.map((s) => s.label);
    const key = JSON.stringify([series, this.xLabel, this.yLabel]);
    if (this.plot && key === this.seriesKey) {
      this.plot.setData(data);
      return;
    }
    this.plot?.destroy();
    this.seriesKey = key;
    this.plot = new uPlot(
      {
        width: widthOf(this.container),
        height: HEIGHT,
        scales: { x: { time: false } },
        axes: [
          { label: this.xLabel, size: 40 },
          { label: this.yLabel, size: 60 },
        ],
        series: [
          { label: 'at', value: (u, v) => (v == null ? '—' : v.toFixed(3)) },
          ...series.map((s) => ({
            label: s.label,
            stroke: s.stroke,
            width: 2,
            dash: s.dash,
            points: { show: false },
            value: (u, v) => (v == null ? '—' : v.toFixed(3)),
          })),
        ],
        cursor: { drag: { x: false, y: false } },
        hooks: { draw: [(u) => this.onDraw?.(u)] },
      },
      data,
      this.container,
    );
  }

  /** What the chart shows, as a table: [header, ...rows] (the API's numbers, unrounded). */
  table() {
    if (!this.data) return [[]];
    const header = [this.xLabel, ...this.seriesLabels];
    const rows = this.data[0].map((x, i) => [x, ...this.data.slice(1).map((ys) => ys[i])]);
    return [header, ...rows];
  }
}

/**
 * The exit-speed curve along the bat with vertical markers (max exit speed,
 * centre of percussion, vibration node) and the sweet zone as a band.
 */
export class CurveChart extends Chart {
  constructor(container) {
    super(container, { yLabel: 'exit speed (m/s)', onDraw: (u) => this.placeMarks(u) });
    this.marks = [];
    this.zone = null;
    this.peak = null;
  }

  /**
   * `curve`: the API's exit_speed_curve; `marks`: [{key, label, position_m}];
   * `zone`: {from_m, to_m} or null; `peak`: {position_m, speed_mps} or null.
   */
  update(curve, marks, zone, peak, axes = {}) {
    const { x = 'position_from_knob_m', y = 'exit_speed_mps' } = axes;
    this.xLabel = axes.xLabel || 'position from the knob (m)';
    this.yLabel = axes.yLabel || 'exit speed (m/s)';
    this.marks = marks;
    this.zone = zone;
    this.peak = peak;
    const xs = curve.map((p) => p[x]);
    const ys = curve.map((p) => p[y]);
    this.show([xs, ys], [{ label: this.yLabel, stroke: PALETTE[0] }]);
    this.placeMarks(this.plot);
  }

  placeMarks(u) {
    if (!u) return;
    for (const old of u.over.querySelectorAll('.u-mark, .u-zone, .u-peak')) old.remove();
    if (this.zone) {
      const left = u.valToPos(this.zone.from ?? this.zone.from_m, 'x');
      const right = u.valToPos(this.zone.to ?? this.zone.to_m, 'x');
      const band = document.createElement('div');
      band.className = 'u-zone';
      band.style.left = `${left}px`;
      band.style.width = `${Math.max(0, right - left)}px`;
      band.dataset.fromM = String(this.zone.from_m);
      band.dataset.toM = String(this.zone.to_m);
      band.title = `sweet zone ${(this.zone.from ?? this.zone.from_m).toFixed(3)}–${(this.zone.to ?? this.zone.to_m).toFixed(3)}`;
      u.over.append(band);
    }
    this.marks.forEach((mark, i) => {
      if (!Number.isFinite(mark.position_m)) return;
      const x = u.valToPos(mark.at ?? mark.position_m, 'x');
      const line = document.createElement('div');
      line.className = `u-mark ${mark.key}`;
      line.style.left = `${x}px`;
      line.dataset.marker = mark.key;
      line.dataset.positionM = String(mark.position_m);
      line.dataset.xPx = x.toFixed(1);
      line.title = `${mark.label}: ${(mark.at ?? mark.position_m).toFixed(4)}`;
      const label = document.createElement('span');
      label.textContent = mark.short;
      label.style.top = `${2 + (i % 3) * 14}px`;
      line.append(label);
      u.over.append(line);
    });
    if (this.peak) {
      const dot = document.createElement('div');
      dot.className = 'u-peak';
      dot.style.left = `${u.valToPos(this.peak.position, 'x')}px`;
      dot.style.top = `${u.valToPos(this.peak.speed, 'y')}px`;
      dot.title = `max exit speed ${this.peak.speed.toFixed(3)}`;
      u.over.append(dot);
    }
  }
}

/** The mode shapes (displacement along the bat) with each mode's nodes. */
export class ModesChart extends Chart {
  constructor(container) {
    super(container, { yLabel: 'displacement (normalised)', onDraw: (u) => this.placeNodes(u) });
    this.nodes = [];
  }

  /**
   * `modes`: the API's modes[] (with shape[] and nodes_from_knob_m). `axes.x`: the key of a
   * shape point's position shown ("position_from_knob_m" or, with report_units imperial, "..._in"),
   * `axes.nodes` the nodes' key in the same unit, `axes.xLabel` the axis label. Each node keeps its
   * position in metres in data-position-m (the API's number, for the tests).
   */
  update(modes, axes = {}) {
    const { x = 'position_from_knob_m', nodes = 'nodes_from_knob_m' } = axes;
    this.xLabel = axes.xLabel || 'position from the knob (m)';
    const xs = modes[0].shape.map((p) => p[x]);
    const sameX = modes.every((m) => m.shape.length === xs.length && m.shape.every((p, i) => p[x] === xs[i]));
    const data = sameX
      ? [xs, ...modes.map((m) => m.shape.map((p) => p.displacement))]
      : uPlot.join(modes.map((m) => [m.shape.map((p) => p[x]), m.shape.map((p) => p.displacement)]));
    this.unit = x.endsWith('_in') ? 'in' : 'm';
    this.container.dataset.xUnit = this.unit; // the axis's unit (its label is drawn, not text)
    this.nodes = modes.map((m, i) => ({
      mode: m.mode,
      color: PALETTE[i + 1],
      nodes: (m[nodes] || []).map((at, k) => ({ at, m: (m.nodes_from_knob_m || [])[k] })),
    }));
    this.show(
      data,
      modes.map((m, i) => ({ label: `mode ${m.mode}: ${m.frequency_hz.toFixed(1)} Hz`, stroke: PALETTE[i + 1] })),
    );
    this.placeNodes(this.plot);
  }

  placeNodes(u) {
    if (!u) return;
    for (const old of u.over.querySelectorAll('.u-node')) old.remove();
    for (const { mode, color, nodes } of this.nodes) {
      for (const { at, m } of nodes) {
        const dot = document.createElement('div');
        dot.className = 'u-node';
        dot.style.left = `${u.valToPos(at, 'x')}px`;
        dot.style.top = `${u.valToPos(0, 'y')}px`;
        dot.style.borderColor = color;
        dot.dataset.mode = String(mode);
        dot.dataset.positionM = String(m);
        dot.title = `mode ${mode} node at ${at.toFixed(this.unit === 'in' ? 2 : 4)} ${this.unit}`;
        u.over.append(dot);
      }
    }
  }
}

/** The variants' exit-speed curves on one chart. */
export class VariantsChart extends Chart {
  constructor(container) {
    super(container, { yLabel: 'exit speed (m/s)' });
  }

  /** `rows`: the API's compare rows, each with exit_speed_curve. */
  update(rows, axes = {}) {
    const { x = 'position_from_knob_m', y = 'exit_speed_mps' } = axes;
    this.xLabel = axes.xLabel || 'position from the knob (m)';
    this.yLabel = axes.yLabel || 'exit speed (m/s)';
    const tables = rows.map((r) => [r.exit_speed_curve.map((p) => p[x]), r.exit_speed_curve.map((p) => p[y])]);
    const xs = tables[0][0];
    const aligned = tables.every((t) => t[0].length === xs.length && t[0].every((x, i) => x === xs[i]));
    const data = aligned ? [xs, ...tables.map((t) => t[1])] : uPlot.join(tables);
    this.show(
      data,
      rows.map((r, i) => ({ label: r.name, stroke: PALETTE[i % PALETTE.length], dash: i === 0 ? undefined : [6, 3] })),
    );
  }
}

/** The batted ball's path from the side: height against the distance toward centre field. */
export class FlightChart extends Chart {
  constructor(container) {
    super(container, { xLabel: 'toward centre field (m)', yLabel: 'height (m)' });
  }

  /**
   * `trajectory`: the API's points; `x`, `y`: their keys to plot (`y_m`/`z_m`,
   * or the `_ft` twins); `unit`: the label's unit.
   */
  update(trajectory, x, y, unit) {
    this.xLabel = `toward centre field (${unit})`;
    this.yLabel = `height (${unit})`;
    this.show(
      [trajectory.map((p) => p[x]), trajectory.map((p) => p[y])],
      [{ label: this.yLabel, stroke: PALETTE[2] }],
    );
  }
}
