// textile viewers (2D and 3D): the texture picker and the mode picker, shared. A mode that declines the texture
// (`declined_modes` of GET /textures/{id}: umbrella on a near-regular exemplar) is offered
// disabled with its reason as the tooltip, and a view asking for it falls back to the default.
'use strict';

window.TextileModes = {
  // Fill `select` with the catalogue's textures, and its landscapes in a group of their own;
  // returns the id to show (`wanted` if the catalogue has it, else the first texture).
  pick(select, catalog, wanted) {
    const group = (label, items) => {
      const g = document.createElement('optgroup');
      g.label = label;
      for (const t of items) g.append(new Option(t.name, t.id));
      select.append(g);
    };
    const landscapes = catalog.landscapes || [];
    group('Textures', catalog.textures);
    if (landscapes.length) group('Landscapes', landscapes);
    return [...catalog.textures, ...landscapes].some((t) => t.id === wanted) ? wanted : catalog.textures[0].id;
  },
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
