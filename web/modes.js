// textile viewers (2D and 3D): the mode picker, shared. A mode that declines the texture
// (`declined_modes` of GET /textures/{id}: umbrella on a near-regular exemplar) is offered
// disabled with its reason as the tooltip, and a view asking for it falls back to the default.
'use strict';

window.TextileModes = {
  // Fill `select` with the texture's modes; returns the mode to show (`wanted` if it serves).
  fill(select, meta, wanted) {
    select.textContent = '';
    const declined = meta.declined_modes || {};
    for (const m of meta.modes) {
      const o = new Option(declined[m] ? `${m} (declines this texture)` : m, m);
      if (declined[m]) { o.disabled = true; o.title = declined[m]; }
      select.append(o);
    }
    const mode = meta.modes.includes(wanted) && !declined[wanted] ? wanted : meta.default_mode;
    select.value = mode;
    return mode;
  },
};
