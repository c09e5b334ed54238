//! [`capture_batch`]: the observation cameras of many envs rendered in one GPU submission.
//!
//! Every env's [`Sensors`] draws through the process-wide [`crate::adapters::RenderContext`],
//! so all their scenes share one device and one mesh store; a vector env renders all of them
//! with one command-buffer submission and one readback (one buffer mapped, one wait) per step
//! instead of one render-and-wait per env.

use std::sync::Arc;

use ms2_render::{Camera, Scene};

use super::{CameraFrame, Sensors};
use crate::adapters::render_scene::render_err;
use crate::error::EnvError;

/// One env's part of a batch: its sensors and the cameras [`Sensors::prepare`] returned.
pub type BatchItem<'a> = (&'a Sensors, &'a [Camera]);

/// Renders every camera of every item and returns one frame per item, in order.
///
/// Items that share a render context (the normal case: [`crate::adapters::RenderContext::shared`])
/// are drawn in one submission; items on other contexts get one submission per context.
/// The images equal those of rendering each env alone ([`Sensors::capture`]).
pub fn capture_batch(items: &[BatchItem<'_>]) -> Result<Vec<CameraFrame>, EnvError> {
    let mut frames: Vec<Option<CameraFrame>> = (0..items.len()).map(|_| None).collect();
    let mut done = vec![false; items.len()];
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
        let mut outputs = ctx
            .renderer()
            .render(&views)
            .map_err(render_err)?
            .into_iter();
        for &k in &group {
            let count = items[k].1.len();
            let mine: Vec<_> = outputs.by_ref().take(count).collect();
            if mine.len() != count {
                return Err(EnvError::Render(format!(
                    "the renderer returned too few images for a batch ({} expected for env {k})",
                    count
                )));
            }
            frames[k] = Some(items[k].0.frame(mine));
            done[k] = true;
        }
    }
    Ok(frames.into_iter().flatten().collect())
}
