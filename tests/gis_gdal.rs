//! GIS clients: GDAL (`gdal-bin`, as QGIS uses it) reads the tiles through the README's
//! `GDAL_WMS` TMS description, pixel-exactly — a 1024² read at any offset equals the server's
//! `/windows` of the same texels.

mod common;

use std::process::Command;

use common::Server;

/// The README's GDAL_WMS description of a texture at its native zoom `z`: a raster of
/// `2^z × 256` pixels a side whose pixel `(x, y)` is texel `(x, y)` of the infinite plane.
fn gdal_wms(base: &str, id: &str, z: u32, query: &str) -> String {
    let side = (1u64 << z) * 256;
    format!(
        r#"<GDAL_WMS>
  <Service name="TMS">
    <ServerUrl>{base}/tiles/{id}/${{z}}/${{x}}/${{y}}.png{query}</ServerUrl>
  </Service>
  <DataWindow>
    <UpperLeftX>0</UpperLeftX>
    <UpperLeftY>0</UpperLeftY>
    <LowerRightX>{side}</LowerRightX>
    <LowerRightY>-{side}</LowerRightY>
    <TileLevel>{z}</TileLevel>
    <TileCountX>1</TileCountX>
    <TileCountY>1</TileCountY>
    <YOrigin>top</YOrigin>
  </DataWindow>
  <BlockSizeX>256</BlockSizeX>
  <BlockSizeY>256</BlockSizeY>
  <BandsCount>3</BandsCount>
  <MaxConnections>4</MaxConnections>
</GDAL_WMS>
"#
    )
}

#[tokio::test]
async fn gdal_reads_tiles_pixel_exactly() {
    if Command::new("gdal_translate").arg("--version").output().is_err() {
        return common::skip("gdal_reads_tiles_pixel_exactly", "no gdal_translate (Debian: apt-get install gdal-bin)");
    }
    let s = Server::builder().start();
    let native = s.json("/textures/gravel").await["native_zoom"].as_u64().unwrap() as u32;
    let dir = tempfile::tempdir().unwrap();
    let xml = dir.path().join("gravel.xml");
    std::fs::write(&xml, gdal_wms(&s.base, "gravel", native, "?seed=3")).unwrap();
    for (x, y) in [(0, 0), (300, 1200)] {
        let out = dir.path().join(format!("read-{x}-{y}.png"));
        let run = Command::new("gdal_translate")
            .args(["-q", "-of", "PNG", "-srcwin", &x.to_string(), &y.to_string(), "1024", "1024"])
            .arg(&xml)
            .arg(&out)
            .env("GDAL_HTTP_TIMEOUT", "60")
            .env("GDAL_DEFAULT_WMS_CACHE_PATH", dir.path().join("cache"))
            .output()
            .expect("gdal_translate");
        assert!(run.status.success(), "gdal_translate: {}", String::from_utf8_lossy(&run.stderr));
        let read = image::open(&out).expect("GDAL's PNG").to_rgb8();
        let window = s.image(&format!("/windows/gravel.png?x={x}&y={y}&w=1024&h=1024&seed=3")).await;
        assert_eq!(read.dimensions(), (1024, 1024));
        let differing = read.pixels().zip(window.pixels()).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "GDAL's read at ({x}, {y}) differs from /windows in {differing} pixels");
    }
}
