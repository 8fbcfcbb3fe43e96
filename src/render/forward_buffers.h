// render/forward_buffers.h — memory the forward pipeline can keep from one render to the next.
// Owns: ForwardBuffers, every large buffer of renderForward (render/hybrid.h): the projected
// window, the stream's block list and its extracted and pending voxels (a window reads them
// there), the compositor's frame, sort and bins. A command that renders many images (bench,
// animate, study) keeps one and passes it in RenderControl::buffers; a single render needs none.
//
// Why: on the virtual machines this project is measured on, the first touch of fresh memory is
// the cost, not the allocation (util/huge_pages.h). A framed Engine render touches ~40 MB of it;
// faulted in on every render, it cost ~10 % of the time with two threads and made the projection
// scale 1.4× instead of 1.9× from one thread to two (docs/performance.md, session 11). The
// buffers grow and never shrink, and each is written before it is read, so an image never
// depends on what they held.
#pragma once
#include "composite/compositor.h"
#include "composite/primitive.h"
#include "volume/stream.h"

namespace vdbsplat {

struct ForwardBuffers {
    /// Keep the level-of-detail moments for the next render of the same grid and table
    /// (StreamOptions::keepMoments). False for a caller that renders once and passes buffers only
    /// so that the render does not free them (`render`: they are freed after the image is
    /// written; freeing them inside the render took 2–10 ms of a one-shot render on this project's
    /// virtual machines, docs/performance.md, session 29).
    bool keepMoments = true;
    StreamWindow voxels;            ///< one window's voxels (runs of the stream's buffers)
    ProjectedWindow window;         ///< one window's primitives
    StreamBuffers stream;           ///< VoxelStream's pending and extracted voxels
    CompositorBuffers compositor;   ///< TileCompositor's frame, sort and bins
};

}  // namespace vdbsplat
