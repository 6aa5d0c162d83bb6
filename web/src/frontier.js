// The optimisation frontier: the best bat at every weight (issue 37, item 3). One
// /v1/optimize request with "frontier" (docs/optimization.md, "The frontier"), run as a
// job on a button press (its progress is the fraction of weights solved), drawn as the
// best exit speed (or the objective) against the weight, the Pareto front joined.
// The problem is the optimisation section's (its rule set, objective, other
// constraints, variables and options); the frontier's weights replace its mass bounds.
import * as api from './api.js';
import { downloadCsv, downloadSvg } from './export.js';
import { clearErrors, el, fmt, readValue, showError } from './form.js';
import { axes, redrawOnResize, scale, svgEl, widthFor } from './svg.js';
import { formOf, setInputSystem } from './units.js';

const $ = (selector) => document.querySelector(selector);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const FINAL_STATES = new Set(['done', 'failed', 'cancelled']);

/** The frontier of the page. */
export class Frontier {
  /** `ctx`: {optimizeBody() the optimisation section's request, saveState(), stem()}. */
  constructor(ctx) {
    this.ctx = ctx;
    this.job = null;
    this.shown = null; // {rows, summary, constraint, xLabel, yLabel, ys}
    const form = $('#frontier-form');
    form.addEventListener('change', () => this.ctx.saveState());
    form.addEventListener('submit', (event) => {
      event.preventDefault();
      this.run();
    });
    $('#frontier-cancel').addEventListener('click', () => this.cancel());
    $('[data-export="frontier-svg"]').addEventListener('click', () =>
      downloadSvg(`${this.ctx.stem()}-frontier.svg`, $('#frontier-chart')),
    );
    $('[data-export="frontier-csv"]').addEventListener('click', () =>
      downloadCsv(`${this.ctx.stem()}-frontier.csv`, this.table()),
    );
    redrawOnResize($('#frontier-chart'), () => this.drawn && this.draw(...this.drawn));
    // The unit switch: a frontier on show is asked again in the new units (after the page's own
    // handler has switched the inputs, hence the timeout).
    $('#units').addEventListener('change', () =>
      setTimeout(() => {
        this.syncPair();
        if (this.drawn) this.run();
      }, 0),
    );
    // A link restored (now, and on every hash change) may leave the pair in two units.
    window.addEventListener('hashchange', () => setTimeout(() => this.syncPair(), 0));
    setTimeout(() => this.syncPair(), 0);
  }

  /**
   * Keeps the two weights in one unit: the request has one constraint name. A weight you
   * typed keeps its text and unit over a switch (docs/explorer.md); the other, still at its
   * default, then takes that unit's default, so nothing is reinterpreted.
   */
  syncPair() {
    const form = $('#frontier-form');
    const pair = [form.elements.frontier_from, form.elements.frontier_to];
    const [a, b] = pair.map((input) => input.dataset.system || 'si');
    if (a === b) return;
    const atDefault = pair.filter((input) => input.value.trim() === formOf(input, input.dataset.system || 'si').value);
    if (atDefault.length !== 1) return; // both typed in two units (a crafted link): run() says so
    const other = pair.find((input) => input !== atDefault[0]);
    const system = other.dataset.system || 'si';
    setInputSystem(atDefault[0], system);
    atDefault[0].value = formOf(atDefault[0], system).value;
    this.ctx.saveState();
  }

  /** The request: the optimisation's, its mass bounds replaced by the frontier's weights. */
  body() {
    const form = $('#frontier-form');
    const from = form.elements.frontier_from;
    const to = form.elements.frontier_to;
    const body = this.ctx.optimizeBody();
    const constraints = { ...body.constraints };
    delete constraints.mass_kg;
    delete constraints.mass_oz;
    const constraint = (from.dataset.system || 'si') === 'imperial' ? 'mass_oz' : 'mass_kg';
    const frontier = { constraint };
    for (const [key, input] of [
      ['from', from],
      ['to', to],
      ['count', form.elements.frontier_count],
    ]) {
      const value = readValue(input);
      if (value !== undefined) frontier[key] = value;
    }
    return { ...body, constraints, frontier };
  }

  showJob(job) {
    const progress = $('#frontier-progress');
    progress.hidden = false;
    progress.value = job.progress || 0;
    const state = $('#frontier-state');
    state.dataset.state = job.state;
    state.dataset.jobId = job.id;
    const percent = Math.round((job.progress || 0) * 100);
    state.textContent =
      job.state === 'running' || job.state === 'queued'
        ? `${job.state}${job.cancel_requested ? ', cancelling' : ''}: ${percent} % of the weights`
        : job.state;
  }

  async run() {
    if (this.running) return;
    this.running = true;
    const form = $('#frontier-form');
    const section = $('#frontier-section');
    clearErrors(form);
    section.dataset.state = 'busy';
    section.setAttribute('aria-busy', 'true');
    $('#frontier-run').disabled = true;
    const body = this.body();
    try {
      // Weights typed in two units (a link can say so): the request has one constraint name,
      // so the page says so instead of sending either number as the other.
      const systems = ['frontier_from', 'frontier_to'].map((name) => form.elements[name].dataset.system || 'si');
      if (systems[0] !== systems[1]) {
        const unit = (system) => (system === 'imperial' ? 'oz' : 'kg');
        showError(form, {
          field: 'frontier',
          message: `the weights are in two units (from in ${unit(systems[0])}, to in ${unit(systems[1])}): type both in one`,
        });
        section.dataset.state = 'error';
        return;
      }
      // The job's body is the optimize request: a refusal may name its fields under "body.".
      const rename = (field) => field.replace(/^body\./, '');
      let job;
      try {
        job = await api.post('/v1/jobs', { path: '/v1/optimize', body });
      } catch (error) {
        showError(form, error, rename);
        section.dataset.state = 'error';
        return;
      }
      this.job = job;
      $('#frontier-cancel').disabled = false;
      this.showJob(job);
      try {
        while (!FINAL_STATES.has(job.state)) {
          await sleep(150);
          job = await api.get(`/v1/jobs/${job.id}`);
          this.showJob(job);
        }
        if (job.state === 'cancelled') {
          section.dataset.state = 'cancelled';
          return;
        }
        const result = await api.get(`/v1/jobs/${job.id}/result`);
        this.draw(result, body);
        section.dataset.state = 'ready';
      } catch (error) {
        showError(form, error, rename);
        section.dataset.state = 'error';
      }
    } finally {
      section.removeAttribute('aria-busy');
      $('#frontier-run').disabled = false;
      $('#frontier-cancel').disabled = true;
      this.job = null;
      this.running = false;
    }
  }

  async cancel() {
    if (!this.job) return;
    $('#frontier-cancel').disabled = true;
    try {
      this.showJob(await api.del(`/v1/jobs/${this.job.id}`));
    } catch (error) {
      showError($('#frontier-form'), error);
    }
  }

  /** Draws the answer {rows, summary} of `body`'s request. */
  draw(result, body) {
    this.drawn = [result, body];
    $('#frontier-figure').hidden = false; // first: the drawing takes its box's width
    const { rows, summary } = result;
    const constraint = summary.constraint;
    const imperial = body.report_units === 'imperial';
    const weightUnit = constraint.endsWith('_oz') ? 'oz' : 'kg';
    // What the chart plots against the weight: the API's number in the answer's units where the
    // answer has one (the sweet spot's exit speed, the MOI about 6 in), else the objective's value
    // in its own unit (the widest sweet zone's width: m, which has no inch twin in the answer).
    const plotted = {
      max_exit_speed: [
        'best exit speed',
        'sweet_spot',
        imperial ? 'exit_speed_mph' : 'exit_speed_mps',
        imperial ? 'mph' : 'm/s',
      ],
      max_exit_speed_swing_weight: [
        'best exit speed, swing-weight adjusted',
        'sweet_spot',
        imperial ? 'exit_speed_mph' : 'exit_speed_mps',
        imperial ? 'mph' : 'm/s',
      ],
      min_moi: [
        'least MOI about 6 in',
        'properties',
        imperial ? 'moi_six_inch_oz_in2' : 'moi_six_inch_kg_m2',
        imperial ? 'oz·in²' : 'kg·m²',
      ],
    }[body.objective];
    const yOf = (row) => (plotted ? row[plotted[1]]?.[plotted[2]] : row.objective_value);
    const yUnit = plotted ? plotted[3] : rows.find((r) => r.objective_unit)?.objective_unit || '';
    const yLabel = `${plotted ? plotted[0] : summary.objective.replaceAll('_', ' ')} (${yUnit})`;
    const xLabel = `weight (${weightUnit})`;
    const pareto = new Set(summary.pareto || []);
    const points = rows.map((row) => ({
      index: row.index,
      x: row[constraint],
      y: yOf(row),
      converged: row.summary?.termination === 'converged',
      pareto: pareto.has(row.index),
      termination: row.summary?.termination || row.code || 'failed',
    }));
    this.shown = { points, xLabel, yLabel };
    const good = points.filter((p) => typeof p.x === 'number' && typeof p.y === 'number');
    const svg = $('#frontier-chart');
    const W = widthFor(svg);
    const H = Math.round(Math.min(300, W * 0.6));
    const box = { left: 64, top: 12, width: W - 64 - 16, height: H - 12 - 46 };
    const xs = good.map((p) => p.x);
    const ys = good.map((p) => p.y);
    const pad = (lo, hi) => (hi > lo ? (hi - lo) * 0.06 : Math.abs(lo) * 0.01 || 1);
    const range = (list) => {
      const [lo, hi] = [Math.min(...list), Math.max(...list)];
      return [lo - pad(lo, hi), hi + pad(lo, hi)];
    };
    const xr = range(xs);
    const yr = range(ys);
    const x = scale(xr[0], xr[1], box.left, box.left + box.width);
    const y = scale(yr[0], yr[1], box.top + box.height, box.top);
    svg.setAttribute('viewBox', `0 0 ${W} ${H}`);
    const front = good.filter((p) => p.pareto).sort((a, b) => a.x - b.x);
    const line = (list) => list.map((p) => `${x(p.x).toFixed(2)},${y(p.y).toFixed(2)}`).join(' ');
    svg.replaceChildren(
      good.length ? axes(box, x, y, xr, yr, xLabel, yLabel) : svgEl('g'),
      svgEl('polyline', { class: 'all', points: line(good) }),
      svgEl('polyline', { class: 'pareto', points: line(front) }),
      ...good.map((p) =>
        svgEl('circle', {
          class: `point${p.pareto ? ' on-front' : ''}${p.converged ? '' : ' unconverged'}`,
          cx: x(p.x).toFixed(2),
          cy: y(p.y).toFixed(2),
          r: p.pareto ? 5 : 4,
          dataset: { index: String(p.index), x: String(p.x), y: String(p.y), pareto: String(p.pareto) },
          title:
            `${fmt(p.x, 4)} ${weightUnit}: ${fmt(p.y, 5)} ${yUnit} ` +
            `(${p.termination}${p.pareto ? ', on the Pareto front' : ''})`,
        }),
      ),
    );
    svg.dataset.points = String(good.length);
    svg.dataset.pareto = (summary.pareto || []).join(',');
    svg.dataset.constraint = constraint;
    $('#frontier-about').replaceChildren(
      el('b', { text: `${summary.termination}: ` }),
      `${summary.message}. ${summary.points} weights, ${summary.continued} answered by the continuation step, ` +
        `${summary.iterations} iterations in ${fmt(summary.solve_time_s * 1000, 3)} ms of solving. ` +
        `Filled and joined: the Pareto front (no other weight is both lighter and better).`,
    );
  }

  /** What the chart shows, a row per weight. */
  table() {
    if (!this.shown) return [[]];
    const { points, xLabel, yLabel } = this.shown;
    return [
      ['index', xLabel, yLabel, 'termination', 'pareto'],
      ...points.map((p) => [p.index, p.x, p.y, p.termination, p.pareto]),
    ];
  }
}
