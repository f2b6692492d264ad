//! The native half of the `skelclimb` Python package. It stays thin: arrays in and out without
//! copies, the GIL released while the Rust extractor runs, errors as Python exceptions. The
//! NumPy-facing conveniences (`marching_cubes`, `Mesh`) are Python, in `python/skelclimb`.

mod arguments;
mod blocks;
mod convert;
mod errors;
mod extract;
mod files;
mod label_blocks;
mod label_shards;
mod labels;
mod recycle;
mod shards;
mod skimage;
mod streamer;
mod world;

use pyo3::prelude::*;

#[global_allocator]
static ALLOCATOR: recycle::Recycling = recycle::Recycling;

/// Frees the memory of dropped meshes that skelclimb keeps for its next call, and returns how
/// many bytes that was.
#[pyfunction]
fn release_memory() -> usize {
    recycle::release()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(extract::extract, m)?)?;
    m.add_function(wrap_pyfunction!(labels::labels, m)?)?;
    m.add_function(wrap_pyfunction!(labels::label_meshes, m)?)?;
    m.add_function(wrap_pyfunction!(skimage::skimage_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(files::save, m)?)?;
    m.add_function(wrap_pyfunction!(files::load, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::block_samples, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::extract_block, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::merge_blocks, m)?)?;
    m.add_function(wrap_pyfunction!(blocks::finish_blocks, m)?)?;
    m.add_function(wrap_pyfunction!(label_blocks::extract_label_block, m)?)?;
    m.add_function(wrap_pyfunction!(label_blocks::merge_label_blocks, m)?)?;
    m.add_function(wrap_pyfunction!(label_blocks::label_block_samples, m)?)?;
    m.add_function(wrap_pyfunction!(label_blocks::finish_label_blocks, m)?)?;
    m.add_function(wrap_pyfunction!(shards::write_shard, m)?)?;
    m.add_function(wrap_pyfunction!(shards::write_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(shards::merge_shards, m)?)?;
    m.add_function(wrap_pyfunction!(shards::shard_kind, m)?)?;
    m.add_function(wrap_pyfunction!(label_shards::write_label_shard, m)?)?;
    m.add_function(wrap_pyfunction!(label_shards::write_label_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(label_shards::merge_label_shards, m)?)?;
    m.add_function(wrap_pyfunction!(release_memory, m)?)?;
    m.add_function(wrap_pyfunction!(arguments::check_threads, m)?)?;
    m.add_function(wrap_pyfunction!(arguments::check_triple, m)?)?;
    m.add_function(wrap_pyfunction!(arguments::check_affine, m)?)?;
    m.add_class::<streamer::SliceStreamer>()?;
    // The modes' names from the runtime's table, which every front end spells them by.
    m.add("MODES", sc_runtime::Mode::NAMES)?;
    Ok(())
}
