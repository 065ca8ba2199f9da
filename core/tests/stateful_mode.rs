//! A mode that prepares something per texture, written outside the core: the `Mode` and
//! `Preparation` traits and one `declare_params!` block are all it needs. The mode ("means")
//! prepares the exemplar's mean colour per 8×8 block, stores it as its own file through the one
//! preparation path (written, read back, a stale or damaged file replaced), and renders from
//! the state it is handed (`Mode::State`, typed: no cast) deterministically. Adding such a mode
//! to the product is its folder in `core/src/modes/` plus its line of `modes!`: nothing else
//! in the core or the server names a mode's state.

use serde_json::{json, Map, Value};
use textile_core::modes::declared::Declared;
use textile_core::modes::{Cost, Mode, Needs, Source, View};
use textile_core::prepare::{envelope, load_or_compute, open_envelope, Input, Origin, Preparation};
use textile_core::{
    AnalysisFileProblem, Cancel, CoreError, Exemplar, ExemplarOptions, NoProgress, Progress, Pyramid, Rect, Rendered,
    RgbWindow,
};

mod common;

/// The prepared state: mean colour of each 8×8 block of the exemplar.
struct Means {
    id: String,
    blocks: u32,
    means: Vec<[u8; 3]>,
}

const MAGIC: &[u8; 8] = b"TESTMEAN";

impl Preparation for Means {
    const WHAT: &'static str = "block means";
    const EXTENSION: &'static str = "means";

    fn id(input: &Input) -> String {
        let mut h = blake3::Hasher::new();
        h.update(b"means-v1");
        input.exemplar.hash_content(&mut h);
        h.finalize().to_hex()[..16].to_string()
    }

    fn compute(input: &Input, _: &dyn Progress, cancel: &Cancel) -> textile_core::Result<Means> {
        cancel.check()?;
        let ex = input.exemplar;
        let blocks = ex.width / 8;
        let mut means = Vec::new();
        for by in 0..blocks {
            for bx in 0..blocks {
                let mut s = [0u32; 3];
                for y in 0..8 {
                    for x in 0..8 {
                        let p = ex.pixels[((by * 8 + y) * ex.width + bx * 8 + x) as usize];
                        (0..3).for_each(|c| s[c] += p[c] as u32);
                    }
                }
                means.push(s.map(|v| (v / 64) as u8));
            }
        }
        Ok(Means { id: Self::id(input), blocks, means })
    }

    fn to_bytes(&self) -> Vec<u8> {
        let body = json!({ "id": self.id, "blocks": self.blocks, "means": self.means });
        envelope(MAGIC, 1, &serde_json::to_vec(&body).unwrap())
    }

    fn from_bytes(bytes: &[u8]) -> Result<Means, AnalysisFileProblem> {
        let body: Value = serde_json::from_slice(open_envelope(MAGIC, 1, bytes)?)
            .map_err(|e| AnalysisFileProblem::Corrupt(e.to_string()))?;
        let bad = || AnalysisFileProblem::Corrupt("fields".into());
        Ok(Means {
            id: body["id"].as_str().ok_or_else(bad)?.to_string(),
            blocks: body["blocks"].as_u64().ok_or_else(bad)? as u32,
            means: serde_json::from_value(body["means"].clone()).map_err(|_| bad())?,
        })
    }

    fn stored_id(&self) -> &str {
        &self.id
    }

    fn describe(&self) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("blocks".into(), json!(self.blocks * self.blocks));
        m
    }

    fn summary(&self) -> String {
        format!("{} blocks", self.means.len())
    }

    fn memory_bytes(&self) -> u64 {
        self.means.len() as u64 * 3
    }
}

textile_core::declare_params! {
    /// The mode's parameters: the seed alone.
    struct MeansParams {
        seed: u64 { default: 0, canonical: "seed=", seed }
    }
    check(_p, _src) { Ok(()) }
}

/// The mode: each pixel the mean of a block drawn by a hash of its 8×8 cell and the seed.
struct BlockMeans;

impl Mode for BlockMeans {
    const NAME: &'static str = "means";
    const VERSION: u32 = 1;
    const SUMMARY: &'static str = "block means of the exemplar, shuffled";
    const NEEDS: Needs = Needs::Prepared;
    const COST: Cost = Cost::Light;
    type Params = MeansParams;
    type State = Means;

    fn render(p: &MeansParams, state: &Means, _: &Source, _: &Pyramid, view: View) -> textile_core::Result<Rendered> {
        let r = view.rect;
        let mut pixels = Vec::with_capacity(r.area() as usize * 3);
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                let h = textile_core::hash::hash(7, p.seed, x.div_euclid(8), y.div_euclid(8), 0);
                pixels.extend_from_slice(&state.means[(h % state.means.len() as u64) as usize]);
            }
        }
        Ok(Rendered {
            image: RgbWindow { width: r.width() as u32, height: r.height() as u32, pixels },
            synthesized: r.area() as u64,
        })
    }
}

fn gravel() -> Exemplar {
    Exemplar::from_bytes(&std::fs::read(common::embedded_exemplar("gravel.png")).unwrap(), &ExemplarOptions::default())
        .unwrap()
}

#[test]
fn a_stateful_mode_prepares_stores_reloads_and_renders_through_the_one_path() {
    let ex = gravel();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("gravel.{}", Means::EXTENSION));
    let input = Input::exemplar(&ex);
    let run = || load_or_compute::<Means>(&input, Some(&path), true, &|| true, &NoProgress, &Cancel::new()).unwrap();
    // Computed and stored, then read back.
    let (first, origin) = run();
    assert!(matches!(origin, Origin::Stored { .. }), "{origin:?}");
    let (second, origin) = run();
    assert_eq!(origin, Origin::Loaded);
    assert_eq!((&first.id, first.summary()), (&second.id, second.summary()));
    // A damaged file is named and replaced, never a panic.
    let mut bytes = std::fs::read(&path).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 0x20;
    std::fs::write(&path, &bytes).unwrap();
    assert!(matches!(run().1, Origin::Stored { why } if why.contains("checksum")));
    // A cancelled preparation stops, and writes nothing.
    let other = dir.path().join("other.means");
    let cancel = Cancel::new();
    cancel.set();
    assert!(matches!(
        load_or_compute::<Means>(&input, Some(&other), true, &|| true, &NoProgress, &cancel),
        Err(CoreError::Cancelled)
    ));
    assert!(!other.exists());
    // Rendered from the state the texture keeps, the same pixels whether it was computed or
    // loaded, and windows are cut from larger ones.
    let p = MeansParams { seed: 5 };
    let render = |state: &Means, rect: Rect| {
        BlockMeans::render(&p, state, &Source::exemplar(&ex), &Pyramid::off(), View::native(rect)).unwrap().image
    };
    let big = render(&first, Rect::new(-40, 30, 64, 48));
    assert_eq!(big, render(&second, Rect::new(-40, 30, 64, 48)));
    let part = render(&second, Rect::new(-24, 38, 16, 16));
    for y in 0..16 {
        let row = |img: &RgbWindow, x0: usize, y0: usize| {
            img.pixels[((y0 + y) * img.width as usize + x0) * 3..][..48].to_vec()
        };
        assert_eq!(row(&part, 0, 0), row(&big, 16, 8));
    }
    // Its parameters come from its one declaration: read, described and keyed.
    let read = MeansParams::default()
        .parse(
            &textile_core::modes::params::Common { seed: Some(9), period: None },
            &mut textile_core::ParamReader::request([("seed", "9")]).unwrap(),
            &Source::exemplar(&ex),
        )
        .unwrap();
    assert_eq!((read.canonical(), read.values(&Source::exemplar(&ex))["seed"].clone()), ("seed=9".into(), json!(9)));
}
