// The unit switch and the page's state in the URL. The page converts no
// number: an input is sent under the field of its own unit (`length_m` or
// `length_in`, docs/api.md "The trade's units"), and answers are asked for
// with `report_units` so that every number shown is one the API computed.

/** The systems of the switch: "imperial" (in, oz, mph) and "si". */
export const SYSTEMS = ['imperial', 'si'];

/** An input's form in `system`: {field, value (its default), unit} from data-si / data-imperial. */
export function formOf(input, system) {
  const [field, value = '', unit = ''] = (input.dataset[system] || '').split('|');
  return { field, value, unit };
}

/** The inputs of `scope` that have a form in each system. */
export function unitInputs(scope) {
  return [...scope.querySelectorAll('input[data-si][data-imperial]')];
}

/** Puts `input` in `system`'s field, unit and label (its value is left to the caller). */
export function setInputSystem(input, system) {
  const form = formOf(input, system);
  const previous = input.dataset.field;
  input.dataset.system = system;
  input.dataset.field = form.field;
  const label = input.closest('label, .field');
  const unit = label?.querySelector('small.unit');
  if (unit) unit.textContent = form.unit;
  const name = label?.querySelector('span.name');
  if (name && name.dataset[system]) name.textContent = name.dataset[system];
  for (const slot of label?.querySelectorAll(`[data-error-for="${CSS.escape(previous)}"]`) || []) {
    slot.dataset.errorFor = form.field;
  }
}

/**
 * Switches the inputs of `scope` to `system`: an input that holds its own
 * system's default takes the new system's default (the defaults are the same
 * conditions, written in each unit: 90 mph = 40.2336 m/s exactly); an input
 * the user changed keeps its text and its unit (so nothing is converted).
 */
export function switchInputs(scope, system) {
  // A group's error slot (a pair's "constraints.mass_kg") follows the switch.
  for (const slot of scope.querySelectorAll('output[data-si][data-imperial]')) {
    slot.dataset.errorFor = slot.dataset[system];
  }
  for (const input of unitInputs(scope)) {
    const own = input.dataset.system || 'si';
    if (own === system) continue;
    if (input.value.trim() === formOf(input, own).value) {
      setInputSystem(input, system);
      input.value = formOf(input, system).value;
    }
  }
}

/** A control's value as the page's HTML sets it. */
function defaultOf(control) {
  if (control.tagName !== 'SELECT') return control.defaultValue;
  const options = [...control.options];
  return (options.find((o) => o.defaultSelected) || options[0])?.value ?? '';
}

/** The page's state that differs from its defaults in `system`, as URL parameters. */
export function stateParams(forms, system) {
  const params = new URLSearchParams();
  params.set('units', system);
  for (const form of forms) {
    for (const control of form.querySelectorAll('input[name], select[name]')) {
      if (control.type === 'radio' || control.type === 'checkbox') continue;
      if (control.dataset.si !== undefined && control.dataset.imperial !== undefined) {
        const own = control.dataset.system || 'si';
        if (own === system && control.value === formOf(control, system).value) continue;
        params.set(control.dataset.field, control.value);
      } else if (control.value !== (control.dataset.default ?? defaultOf(control))) {
        params.set(control.name, control.value);
      }
    }
  }
  return params;
}

/**
 * Restores a state written by stateParams onto `forms` (after the switch to
 * its system): each key is a control's name, or a unit input's field in either
 * system. Returns the keys no control took.
 */
export function restoreParams(forms, params) {
  const unknown = [];
  for (const [key, value] of params) {
    if (key === 'units') continue;
    let taken = false;
    for (const form of forms) {
      for (const input of unitInputs(form)) {
        for (const system of SYSTEMS) {
          if (formOf(input, system).field === key) {
            setInputSystem(input, system);
            input.value = value;
            taken = true;
          }
        }
      }
      const control = !taken && form.querySelector(`[name="${CSS.escape(key)}"]`);
      if (control && control.type !== 'radio') {
        control.value = value;
        taken = true;
      }
    }
    if (!taken) unknown.push(key);
  }
  return unknown;
}

/** Puts every control of `forms` back to the page's defaults, unit inputs in SI (then switch). */
export function resetControls(forms) {
  for (const form of forms) {
    for (const control of form.querySelectorAll('input[name], select[name]')) {
      if (control.type === 'radio' || control.type === 'checkbox') continue;
      if (control.dataset.si !== undefined && control.dataset.imperial !== undefined) {
        setInputSystem(control, 'si');
        control.value = formOf(control, 'si').value;
      } else {
        control.value = control.dataset.default ?? defaultOf(control);
      }
    }
  }
}
