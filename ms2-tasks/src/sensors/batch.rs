//! Batched capture: the observation cameras of many envs rendered in one GPU submission.
//!
//! Every env's [`Sensors`] draws through the process-wide [`crate::adapters::RenderContext`],
//! so all their scenes share one device and one mesh store; a vector env renders all of them
//! with one command-buffer submission and one readback (one buffer mapped, one wait) instead
//! of one render-and-wait per env. [`submit_batch`] returns at once, so the caller can step
//! other envs' physics while the batch renders; [`PendingBatch::wait`] collects the frames.

use std::sync::Arc;

use ms2_render::{Camera, PendingFrame, Scene};

use super::{CameraFrame, Sensors};
use crate::adapters::render_scene::render_err;
use crate::error::EnvError;

/// One env's part of a batch: its sensors and the cameras [`Sensors::prepare`] returned.
pub type BatchItem<'a> = (&'a Sensors, &'a [Camera]);

/// A submitted batch: one pending GPU submission per render context (normally one).
pub struct PendingBatch {
    /// Per submission: the pending images and, per item it covers, (item index, empty frame).
    submissions: Vec<(PendingFrame, Vec<(usize, CameraFrame)>)>,
    items: usize,
}

impl std::fmt::Debug for PendingBatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PendingBatch")
            .field("submissions", &self.submissions.len())
            .field("items", &self.items)
            .finish()
    }
}

/// Encodes and submits every camera of every item without waiting.
///
/// Items that share a render context (the normal case: [`crate::adapters::RenderContext::shared`])
/// are drawn in one submission; items on other contexts get one submission per context.
pub fn submit_batch(items: &[BatchItem<'_>]) -> Result<PendingBatch, EnvError> {
    let mut done = vec![false; items.len()];
    let mut submissions = Vec::new();
    for first in 0..items.len() {
        if done[first] {
            continue;
        }
        let ctx = items[first].0.context();
        let group: Vec<usize> = (first..items.len())
            .filter(|&k| !done[k] && Arc::ptr_eq(items[k].0.context(), ctx))
            .collect();
        let views: Vec<(&Scene, &[Camera])> = group
            .iter()
            .map(|&k| (items[k].0.scene(), items[k].1))
            .collect();
        let pending = ctx.renderer().submit_sensors(&views).map_err(render_err)?;
        let frames = group
            .iter()
            .map(|&k| {
                done[k] = true;
                (k, items[k].0.frame(Vec::with_capacity(items[k].1.len())))
            })
            .collect();
        submissions.push((pending, frames));
    }
    Ok(PendingBatch {
        submissions,
        items: items.len(),
    })
}

impl PendingBatch {
    /// Waits for the images and returns one frame per item, in submission order.
    pub fn wait(self) -> Result<Vec<CameraFrame>, EnvError> {
        let mut frames: Vec<Option<CameraFrame>> = (0..self.items).map(|_| None).collect();
        for (pending, group) in self.submissions {
            let mut outputs = pending.wait().map_err(render_err)?.into_iter();
            for (k, mut frame) in group {
                frame
                    .outputs
                    .extend(outputs.by_ref().take(frame.uids.len()));
                if frame.outputs.len() != frame.uids.len() {
                    return Err(EnvError::Render(format!(
                        "the renderer returned too few images for env {k} of a batch"
                    )));
                }
                frames[k] = Some(frame);
            }
        }
        Ok(frames.into_iter().flatten().collect())
    }
}

/// Renders every camera of every item and returns one frame per item, in order
/// ([`submit_batch`] then [`PendingBatch::wait`]). The images equal those of rendering each
/// env alone ([`Sensors::capture`]).
pub fn capture_batch(items: &[BatchItem<'_>]) -> Result<Vec<CameraFrame>, EnvError> {
    submit_batch(items)?.wait()
}
