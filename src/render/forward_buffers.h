// render/forward_buffers.h — memory the forward pipeline can keep from one render to the next.
// Owns: ForwardBuffers, every large buffer of renderForward (render/hybrid.h): the projected
// window, the stream's block list and its extracted and pending voxels (a window reads them
// there), the compositor's frame, sort and bins; the footprint tables read for the first render
// (KeptTables) and an output image the caller is done with (recycle). A command that renders many
// images (bench, animate, study, render --warmup) keeps one and passes it in
// RenderControl::buffers; a single render needs none.
//
// Why: on the virtual machines this project is measured on, the first touch of fresh memory is
// the cost, not the allocation (util/huge_pages.h). A framed Engine render touches ~40 MB of it;
// faulted in on every render, it cost ~10 % of the time with two threads and made the projection
// scale 1.4× instead of 1.9× from one thread to two (docs/performance.md, session 11). The
// buffers grow and never shrink, and each is written before it is read, so an image never
// depends on what they held.
#pragma once
#include <filesystem>
#include <memory>
#include <optional>

#include "composite/compositor.h"
#include "composite/primitive.h"
#include "footprint/tables.h"
#include "image/image.h"
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

    /// The footprint tables one render read (render/pending_tables.h), lent to the next ones that
    /// ask for the same directory and kernel: reading and checking the two files and fitting the
    /// polynomials again took ~25 fresh pages and a worker's 0.3 ms every render (a warm far
    /// render is 1–5 ms; docs/performance.md, session 47). A command reads its tables once.
    struct KeptTables {
        std::filesystem::path dir;
        const KernelShape* kernel = nullptr;  ///< one of KernelShape's named kernels
        std::shared_ptr<const Tables> tables;
    };
    std::optional<KeptTables> tables;

    /// @brief Gives back an image the caller is done with: the next render writes its data window
    /// into that memory (takeImage) instead of fresh pages (a far 1024² window is 180 KB: the
    /// heap grew for it, ~26 page faults, every warm render).
    void recycle(WindowedImage&& image) { spare_ = std::move(image.data); }
    /// @brief A @p width × @p height image whose every pixel the caller writes: the recycled one's
    /// memory where it holds as many pixels (its values are stale, not zero), else a new one.
    Image takeImage(int width, int height);

private:
    Image spare_;
};

}  // namespace vdbsplat
