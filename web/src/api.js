// The public API, and nothing else: every number the page shows comes from
// one of these calls (docs/api.md). Errors keep the API's own envelope
// {code, message, field} so the page can show `message` beside `field`.

const TOKEN_KEY = 'sweetspot-token';

/** An error answer of the API (or a network failure, code "Network"). */
export class ApiError extends Error {
  constructor(status, body) {
    super(body && body.message ? body.message : `HTTP ${status}`);
    this.status = status;
    this.code = (body && body.code) || 'Network';
    this.field = (body && body.field) || null;
    this.body = body;
  }
}

/** The bearer token the user pasted for this tab ("" when none). */
export function token() {
  try {
    return sessionStorage.getItem(TOKEN_KEY) || '';
  } catch {
    return '';
  }
}

/** Keeps `value` as this tab's token (empty: forget it). */
export function setToken(value) {
  try {
    if (value) sessionStorage.setItem(TOKEN_KEY, value);
    else sessionStorage.removeItem(TOKEN_KEY);
  } catch {
    // Storage disabled: the token lives until the page is reloaded.
  }
  memoryToken = value;
}
let memoryToken = '';

/** Called with the error when the server asks for a token (401). */
let onUnauthorized = () => {};
export function setUnauthorizedHandler(handler) {
  onUnauthorized = handler;
}

/**
 * One request: resolves to the parsed JSON body of a 2xx answer; rejects with
 * an ApiError carrying the API's code, message and field otherwise.
 */
export async function call(method, path, body) {
  const headers = { Accept: 'application/json' };
  const bearer = token() || memoryToken;
  if (bearer) headers.Authorization = `Bearer ${bearer}`;
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  let response;
  try {
    response = await fetch(path, {
      method,
      headers,
      body: body === undefined ? undefined : JSON.stringify(body),
      cache: 'no-store',
    });
  } catch (error) {
    throw new ApiError(0, { code: 'Network', message: `the server did not answer (${error.message})` });
  }
  let json = null;
  try {
    json = await response.json();
  } catch {
    json = null;
  }
  if (!response.ok) {
    const error = new ApiError(response.status, json);
    if (response.status === 401) onUnauthorized(error);
    throw error;
  }
  return json;
}

/** GET `path`. */
export const get = (path) => call('GET', path);
/** POST `body` to `path`. */
export const post = (path, body) => call('POST', path, body);
/** DELETE `path`. */
export const del = (path) => call('DELETE', path);
