//! How it works: the few GDAL calls the `gdal` crate does not wrap, each behind a safe function,
//! so that this is the only file of the builder with `unsafe` in it.
//!
//! `warped_vrt` runs `gdalwarp` as a library call with `-of VRT`: the result is a *warped virtual
//! dataset* held in memory, which computes its pixels block by block when they are read. Reading a
//! window of it therefore costs only that window's warp, and memory stays flat whatever the input.

use std::ffi::{CStr, CString, c_char};
use std::ptr;

use gdal::Dataset;
use gdal::spatial_ref::SpatialRef;

/// The last message GDAL logged, or a placeholder when it logged none.
fn last_gdal_message() -> String {
    // SAFETY: CPLGetLastErrorMsg returns a pointer to a thread-local, NUL-terminated buffer that
    // stays valid until the next GDAL call on this thread; it is copied out at once.
    let message = unsafe { CStr::from_ptr(gdal_sys::CPLGetLastErrorMsg()) };
    match message.to_string_lossy().trim() {
        "" => "GDAL gave no reason".to_owned(),
        text => text.to_owned(),
    }
}

/// Parsed `gdalwarp` options, freed on drop.
struct WarpOptions(*mut gdal_sys::GDALWarpAppOptions);

impl WarpOptions {
    fn new(args: &[String]) -> Result<Self, String> {
        let args: Vec<CString> = args
            .iter()
            .map(|a| CString::new(a.as_str()).map_err(|_| format!("warp argument {a:?} holds a NUL byte")))
            .collect::<Result<_, _>>()?;
        let mut argv: Vec<*mut c_char> =
            args.iter().map(|a| a.as_ptr().cast_mut()).chain(std::iter::once(ptr::null_mut())).collect();
        // SAFETY: `argv` is a NULL-terminated array of NUL-terminated strings that outlive the call;
        // GDAL copies what it keeps and does not write through the pointers.
        let options = unsafe { gdal_sys::GDALWarpAppOptionsNew(argv.as_mut_ptr(), ptr::null_mut()) };
        if options.is_null() {
            return Err(format!("bad warp options {args:?}: {}", last_gdal_message()));
        }
        Ok(Self(options))
    }
}

impl Drop for WarpOptions {
    fn drop(&mut self) {
        // SAFETY: the pointer came from GDALWarpAppOptionsNew and is freed exactly once.
        unsafe { gdal_sys::GDALWarpAppOptionsFree(self.0) };
    }
}

/// A warped VRT of `source` built by the `gdalwarp` arguments `args` (without file names).
///
/// The VRT refers to `source`'s handle: the caller must keep `source` open for as long as the
/// returned dataset lives.
pub fn warped_vrt(source: &Dataset, args: &[String]) -> Result<Dataset, String> {
    let options = WarpOptions::new(args)?;
    let mut sources = [source.c_dataset()];
    let mut usage_error = 0;
    // An empty destination name keeps the VRT in memory: it is never written anywhere.
    let destination = c"";
    // SAFETY: every pointer is valid for the duration of the call; `sources` holds one open
    // dataset handle; GDAL returns a new dataset handle (owned by us) or NULL on failure.
    let warped = unsafe {
        gdal_sys::GDALWarp(
            destination.as_ptr(),
            ptr::null_mut(),
            1,
            sources.as_mut_ptr(),
            options.0,
            &mut usage_error,
        )
    };
    if warped.is_null() {
        return Err(format!("warping failed: {}", last_gdal_message()));
    }
    // SAFETY: `warped` is a fresh, open dataset handle that nothing else owns.
    Ok(unsafe { Dataset::from_c_dataset(warped) })
}

/// The azimuthal equidistant projection centred on (`lat_deg`, `lon_deg`) over the geographic
/// CRS `geographic` (same datum and ellipsoid), in metres.
pub fn azimuthal_equidistant(
    geographic: &SpatialRef,
    lat_deg: f64,
    lon_deg: f64,
) -> Result<SpatialRef, String> {
    let projected = geographic.clone();
    // SAFETY: `projected` owns a valid OGRSpatialReferenceH for the duration of the call. On a
    // geographic CRS, OSRSetAE builds a projected CRS around it (GDAL's documented pattern).
    let err = unsafe { gdal_sys::OSRSetAE(projected.to_c_hsrs(), lat_deg, lon_deg, 0.0, 0.0) };
    if err != gdal_sys::OGRErr::OGRERR_NONE {
        return Err(format!("building the local frame: {}", last_gdal_message()));
    }
    Ok(projected)
}

/// Sets GDAL's raster block cache, in bytes (it defaults to 5 % of the machine's memory).
pub fn set_block_cache_bytes(bytes: i64) {
    // SAFETY: a plain setter of a global, callable at any time.
    unsafe { gdal_sys::GDALSetCacheMax64(bytes) };
}

/// The CRS's TOWGS84 Helmert parameters (translation m, rotation ″, scale ppm; position vector),
/// or `None` where its datum carries none.
pub fn towgs84(srs: &SpatialRef) -> Option<[f64; 7]> {
    let mut params = [0.0f64; 7];
    // SAFETY: `srs` is a live spatial reference for the call; GDAL writes at most the 7 doubles
    // the count allows into the array, which outlives the call.
    let err = unsafe { gdal_sys::OSRGetTOWGS84(srs.to_c_hsrs(), params.as_mut_ptr(), 7) };
    (err == gdal_sys::OGRErr::OGRERR_NONE).then_some(params)
}
