//! A replay on a thread of its own, fed jobs through a channel: the shape the MCP server's
//! replay and the inspector's worker share. Dropping the handle closes the channel, so the
//! thread's loop ends after the job it is on, and then waits for the thread: no replay is still
//! using the device when its owner is gone.

use std::sync::mpsc::{Receiver, Sender, channel};
use std::thread::JoinHandle;

/// The owner's end of a worker thread taking jobs of type `J`.
pub struct Worker<J> {
    jobs: Option<Sender<J>>,
    thread: Option<JoinHandle<()>>,
}

impl<J: Send + 'static> Worker<J> {
    /// Starts `serve` on a thread named `name`, handing it the receiving end of the jobs.
    /// Where no thread can be started, jobs sent are refused (`send` returns false).
    pub fn start(name: &str, serve: impl FnOnce(Receiver<J>) + Send + 'static) -> Worker<J> {
        let (jobs, inbox) = channel::<J>();
        let thread = std::thread::Builder::new()
            .name(name.to_owned())
            .spawn(move || serve(inbox))
            .ok();
        Worker {
            jobs: thread.as_ref().map(|_| jobs),
            thread,
        }
    }

    /// Hands the worker a job; `false` when it has stopped.
    pub fn send(&self, job: J) -> bool {
        self.jobs.as_ref().is_some_and(|j| j.send(job).is_ok())
    }
}

impl<J> Drop for Worker<J> {
    fn drop(&mut self) {
        self.jobs = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl<J> std::fmt::Debug for Worker<J> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Worker")
            .field("running", &self.thread.is_some())
            .finish()
    }
}
