import { a as e, i as t, n, o as r, r as i, s as a, t as o } from "./plugins-RoDI5SD7.js";
export { a as CesiumIonAuth, t as CesiumIonAuthPlugin, n as EnforceNonZeroErrorPlugin, r as GoogleCloudAuth, e as GoogleCloudAuthPlugin, i as ImplicitTilingPlugin, o as QuantizedMeshLoaderBase };
