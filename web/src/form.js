// Form helpers: inputs are read as the API expects them (no validation in the
// browser: the API's own message is shown beside the field it names).

/**
 * The value of a text input for a request: blank = undefined (the API's
 * default applies), a number = that number, anything else = the text itself
 * (so that the API says what is wrong with it).
 */
export function readValue(input) {
  const text = input.value.trim();
  if (text === '') return undefined;
  const number = Number(text);
  return Number.isFinite(number) ? number : text;
}

/** Sets obj[a][b]... = value for the dotted `path` ("ball.speed_mps"); skips undefined. */
export function setPath(obj, path, value) {
  if (value === undefined) return obj;
  const keys = path.split('.');
  let at = obj;
  for (const key of keys.slice(0, -1)) {
    if (typeof at[key] !== 'object' || at[key] === null) at[key] = {};
    at = at[key];
  }
  at[keys[keys.length - 1]] = value;
  return obj;
}

/**
 * Every enabled `[data-field]` input inside `scope` whose field starts with
 * `prefix`, into one object (keys relative to the prefix unless `keepPrefix`).
 */
export function readFields(scope, prefix, keepPrefix = false, out = {}) {
  for (const input of scope.querySelectorAll('[data-field]')) {
    const field = input.dataset.field;
    if (!field.startsWith(prefix) || input.disabled || input.tagName === 'SELECT') continue;
    setPath(out, keepPrefix ? field : field.slice(prefix.length), readValue(input));
  }
  return out;
}

/** True when `key` is `field` or a path prefix of it ("a.b" of "a.b.c" or "a.b[2]"). */
function covers(key, field) {
  return field === key || field.startsWith(`${key}.`) || field.startsWith(`${key}[`);
}

/** Empties every error slot inside `scope` and un-marks its inputs. */
export function clearErrors(scope) {
  for (const slot of scope.querySelectorAll('[data-error-for]')) {
    slot.textContent = '';
    slot.hidden = true;
  }
  for (const input of scope.querySelectorAll('[aria-invalid="true"]')) {
    input.removeAttribute('aria-invalid');
  }
}

/**
 * Shows an ApiError's message in the slot of `scope` that names its field (or
 * the longest prefix of it), else in the slot `data-error-for="*"`. `rename`
 * maps the API's field to the page's (e.g. "variants[1].bat.fill" to a
 * variant's checkbox). Returns the slot used.
 */
export function showError(scope, error, rename = (field) => field) {
  const field = error.field ? rename(error.field) : '';
  let best = null;
  for (const slot of scope.querySelectorAll('[data-error-for]')) {
    const key = slot.dataset.errorFor;
    if (key === '*' || !field || !covers(key, field)) continue;
    if (!best || key.length > best.dataset.errorFor.length) best = slot;
  }
  const slot = best || scope.querySelector('[data-error-for="*"]');
  if (!slot) return null;
  const text = error.code && error.code !== 'Network' ? `${error.message} (${error.code})` : error.message;
  slot.textContent = slot.textContent ? `${slot.textContent}; ${text}` : text;
  slot.hidden = false;
  slot.dataset.code = error.code || '';
  slot.dataset.apiField = error.field || '';
  if (best) {
    for (const input of scope.querySelectorAll(`[data-field="${CSS.escape(best.dataset.errorFor)}"]`)) {
      input.setAttribute('aria-invalid', 'true');
    }
  }
  return slot;
}

/** A number for display: `digits` significant digits, or "—". */
export function fmt(value, digits = 4) {
  if (typeof value !== 'number' || !Number.isFinite(value)) return '—';
  const abs = Math.abs(value);
  if (abs !== 0 && (abs < 1e-3 || abs >= 1e5)) return value.toExponential(digits - 1);
  return Number(value.toPrecision(digits)).toString();
}

/** A signed difference for display ("+0.0123"). */
export function fmtDelta(value, digits = 3) {
  if (typeof value !== 'number' || !Number.isFinite(value)) return '';
  return `${value >= 0 ? '+' : '−'}${fmt(Math.abs(value), digits)}`;
}

/** Creates an element with attributes and children. */
export function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs)) {
    if (value === undefined || value === null || value === false) continue;
    if (key === 'dataset') Object.assign(node.dataset, value);
    else if (key === 'text') node.textContent = value;
    else node.setAttribute(key, value === true ? '' : String(value));
  }
  for (const child of children.flat()) {
    if (child === null || child === undefined) continue;
    node.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return node;
}
