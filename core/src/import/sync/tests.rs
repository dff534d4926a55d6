//! The checker's rules, each on the smallest case that shows it.

use super::state::State;
use super::*;

#[test]
fn scopes_reach_logically_earlier_and_later_stages() {
    assert!(earlier(S::FRAGMENT_SHADER).intersects(S::VERTEX_SHADER));
    assert!(!earlier(S::VERTEX_SHADER).intersects(S::FRAGMENT_SHADER));
    assert!(!earlier(S::TOP_OF_PIPE).intersects(S::COLOR_ATTACHMENT_OUTPUT));
    assert!(earlier(S::BOTTOM_OF_PIPE).intersects(S::TRANSFER));
    assert!(later(S::TOP_OF_PIPE).intersects(S::COMPUTE_SHADER));
    assert!(!later(S::BOTTOM_OF_PIPE).intersects(S::FRAGMENT_SHADER));
    assert!(later(S::VERTEX_SHADER).intersects(S::COLOR_ATTACHMENT_OUTPUT));
    assert!(earlier(S::COPY).intersects(S::TRANSFER));
}

fn acc(stage: S, access: A) -> Access {
    Access {
        stage,
        access,
        command: Origin::none("cmd"),
        what: What::Text(""),
    }
}

/// vkBasalt's mip chain: a blit's write transitioned by a barrier whose second scope is the
/// vertex shader, then sampled by a fragment shader. The barrier orders the fragment read (a
/// logically later stage) but makes the write visible only to the vertex shader's accesses:
/// access scopes are not extended to later stages, and the validation layer reports the read.
#[test]
fn a_barrier_makes_writes_visible_only_to_the_stages_it_names() {
    let mut st = State::default();
    assert!(
        st.write(acc(S::TRANSFER, A::TRANSFER_WRITE), 0, 0)
            .is_empty()
    );
    let to_vertex = Dep {
        src: earlier(S::TRANSFER),
        src_access: A::TRANSFER_WRITE,
        dst: later(S::VERTEX_SHADER),
        dst_visible: stages::canonical(S::VERTEX_SHADER),
        dst_access: A::SHADER_READ.expand(),
    };
    st.depend(&to_vertex);
    assert!(to_vertex.dst.intersects(S::FRAGMENT_SHADER), "ordered");
    let h = st
        .clone()
        .read(acc(S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ), 0);
    assert_eq!(h.map(|h| h.0), Some(HazardKind::ReadAfterWrite));
    assert!(
        st.read(acc(S::VERTEX_SHADER, A::SHADER_SAMPLED_READ), 0)
            .is_none()
    );
}

#[test]
fn a_write_needs_a_memory_dependency_to_be_read() {
    let mut st = State::default();
    assert!(
        st.write(acc(S::TRANSFER, A::TRANSFER_WRITE), 0, 0)
            .is_empty()
    );
    // No barrier: the read sees nothing.
    let mut unordered = st.clone();
    let h = unordered.read(acc(S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ), 0);
    assert_eq!(h.map(|h| h.0), Some(HazardKind::ReadAfterWrite));
    // An execution dependency alone does not make the write visible.
    let mut exec_only = st.clone();
    exec_only.depend(&Dep {
        src: earlier(S::TRANSFER),
        src_access: A::EMPTY,
        dst: later(S::FRAGMENT_SHADER),
        dst_visible: S::FRAGMENT_SHADER,
        dst_access: A::SHADER_READ.expand(),
    });
    assert!(
        exec_only
            .read(acc(S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ), 0)
            .is_some()
    );
    // The full dependency does.
    st.depend(&Dep {
        src: earlier(S::TRANSFER),
        src_access: A::TRANSFER_WRITE,
        dst: later(S::FRAGMENT_SHADER),
        dst_visible: S::FRAGMENT_SHADER,
        dst_access: A::SHADER_READ.expand(),
    });
    assert!(
        st.read(acc(S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ), 0)
            .is_none()
    );
    // A later write must wait for that read; the read, ordered after the first write,
    // orders the two writes.
    let h = st.clone().write(acc(S::TRANSFER, A::TRANSFER_WRITE), 0, 0);
    let kinds: Vec<HazardKind> = h.iter().map(|h| h.0).collect();
    assert_eq!(kinds, [HazardKind::WriteAfterRead]);
}

#[test]
fn a_write_unordered_with_the_read_before_it_is_a_write_after_read() {
    // A layout transition made visible to shader reads, a compute read, then a compute
    // write with no dependency on either (a weakened barrier between two dispatches):
    // the read is the access it must wait for.
    let mut st = State::default();
    let to_reads = Dep {
        src: earlier(S::TRANSFER),
        src_access: A::TRANSFER_WRITE,
        dst: later(S::COMPUTE_SHADER),
        dst_visible: S::COMPUTE_SHADER,
        dst_access: A::SHADER_READ.expand(),
    };
    assert!(
        st.transition(&to_reads, acc(S::EMPTY, A::EMPTY), 0, 0)
            .is_empty()
    );
    assert!(
        st.read(acc(S::COMPUTE_SHADER, A::SHADER_STORAGE_READ), 0)
            .is_none()
    );
    let weak = Dep {
        src: earlier(S::TRANSFER),
        src_access: A::EMPTY,
        dst: later(S::COMPUTE_SHADER),
        dst_visible: S::COMPUTE_SHADER,
        dst_access: A::SHADER_WRITE.expand(),
    };
    let mut unordered = st.clone();
    unordered.depend(&weak);
    let kinds: Vec<HazardKind> = unordered
        .write(acc(S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE), 0, 0)
        .iter()
        .map(|h| h.0)
        .collect();
    assert_eq!(kinds, [HazardKind::WriteAfterRead]);
    // The barrier as recorded (its first scope reaches the compute stage) orders both.
    st.depend(&Dep {
        src: earlier(S::COMPUTE_SHADER),
        src_access: A::SHADER_READ.expand(),
        ..weak
    });
    assert!(
        st.write(acc(S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE), 0, 0)
            .is_empty()
    );
}

#[test]
fn a_layout_transition_is_a_write_its_barrier_must_make_visible() {
    let mut st = State::default();
    let d = Dep {
        src: earlier(S::TRANSFER),
        src_access: A::TRANSFER_WRITE,
        dst: later(S::COLOR_ATTACHMENT_OUTPUT),
        dst_visible: S::COLOR_ATTACHMENT_OUTPUT,
        dst_access: A::COLOR_ATTACHMENT_WRITE,
    };
    st.write(acc(S::TRANSFER, A::TRANSFER_WRITE), 0, 0);
    assert!(st.transition(&d, acc(S::EMPTY, A::EMPTY), 0, 0).is_empty());
    // loadOp LOAD reads the attachment: the barrier made the transition visible to
    // writes only (mpv's frames).
    let h = st.read(acc(S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_READ), 0);
    assert_eq!(h.map(|h| h.0), Some(HazardKind::ReadAfterWrite));
}

/// Two layout transitions with nothing ordering them (a render pass's initial transition
/// under its implicit external dependency after a barrier's): on one queue they happen in
/// submission order, as the validation layer has it; across queues the second is a hazard.
#[test]
fn sequential_layout_transitions_on_one_queue_are_ordered() {
    let unordered = Dep {
        src: S::EMPTY,
        src_access: A::EMPTY,
        dst: later(S::COLOR_ATTACHMENT_OUTPUT),
        dst_visible: S::COLOR_ATTACHMENT_OUTPUT,
        dst_access: A::COLOR_ATTACHMENT_WRITE,
    };
    let transition = || Access {
        what: What::Transition(
            ImageLayout::ShaderReadOnlyOptimal,
            ImageLayout::ColorAttachmentOptimal,
        ),
        ..acc(S::EMPTY, A::EMPTY)
    };
    let mut st = State::default();
    assert!(st.transition(&unordered, transition(), 0, 7).is_empty());
    assert!(
        st.clone()
            .transition(&unordered, transition(), 0, 7)
            .is_empty()
    );
    let h = st.transition(&unordered, transition(), 0, 8);
    assert_eq!(h.first().map(|h| h.0), Some(HazardKind::WriteAfterWrite));
    // A transition after an ordinary write still needs the write in its barrier's scope.
    let mut st = State::default();
    st.write(acc(S::TRANSFER, A::TRANSFER_WRITE), 0, 7);
    let h = st.transition(&unordered, transition(), 0, 7);
    assert_eq!(h.first().map(|h| h.0), Some(HazardKind::WriteAfterWrite));
}

/// A buffer written on queue family 0 and read on family 1, each in its own submission,
/// the read waiting on a semaphore the write's submission signalled.
fn across_families(release_and_acquire: bool) -> Vec<HazardKind> {
    let objects = Objects::default();
    let mut sync = Sync::new(true);
    let at = |command: &'static str, stage: S, access: A| Access {
        stage,
        access,
        command: Origin::none(command),
        what: What::Text(""),
    };
    let transfer = |family_side: bool| BarrierCmd {
        origin: Origin::none(if family_side { "release" } else { "acquire" }),
        target: BarrierTarget::Buffer {
            buffer: 1,
            range: (0, u64::MAX),
        },
        src_stages: S::TRANSFER,
        dst_stages: S::COMPUTE_SHADER,
        src_access: A::TRANSFER_WRITE,
        dst_access: A::SHADER_READ,
        layouts: None,
        families: Some((0, 1)),
    };
    sync.family = Some(0);
    sync.seq = 1;
    sync.access(
        &[Key::Buffer {
            buffer: 1,
            start: 0,
        }],
        true,
        &at("write", S::COPY, A::TRANSFER_WRITE),
    );
    if release_and_acquire {
        sync.barrier(&objects, &transfer(true), true);
    }
    sync.signalled.insert(9, vec![(None, 1)]);
    sync.family = Some(1);
    sync.semaphore_wait(9, S::TOP_OF_PIPE, None);
    sync.seq = 2;
    if release_and_acquire {
        sync.barrier(&objects, &transfer(false), true);
    }
    sync.access(
        &[Key::Buffer {
            buffer: 1,
            start: 0,
        }],
        false,
        &at("read", S::COMPUTE_SHADER, A::SHADER_STORAGE_READ),
    );
    sync.found.keys().map(|(_, _, kind)| *kind).collect()
}

#[test]
fn an_exclusive_resource_read_on_another_family_needs_its_ownership_transferred() {
    assert_eq!(
        across_families(false),
        [HazardKind::OwnershipTransferMissing]
    );
    assert!(across_families(true).is_empty());
}

#[test]
fn a_timeline_wait_is_for_the_first_signal_of_its_value() {
    let mut sync = Sync::new(true);
    sync.signalled
        .insert(5, vec![(Some(1), 1), (Some(2), 2), (Some(3), 3)]);
    sync.signalled.insert(6, vec![(None, 1), (None, 4)]);
    assert_eq!(sync.signal_for(5, Some(2)), Some(2));
    assert_eq!(
        sync.signal_for(5, Some(4)),
        None,
        "not signalled in the frames"
    );
    assert_eq!(
        sync.signal_for(6, None),
        Some(4),
        "a binary semaphore's last signal"
    );
}

/// zink's glmark2 terrain: a transition made visible to fragment-shader reads, a fragment read
/// of it, a barrier on another image whose first scope reaches that read (colour output is
/// logically after the fragment shader) and whose second is the vertex shader, then a vertex
/// read. The other image's barrier orders the vertex read after the fragment read (execution
/// dependencies are not limited to a barrier's resources), and a read ordered after a read of
/// the write is not checked against the write again, as the validation layer does.
#[test]
fn a_read_ordered_after_a_read_of_the_write_is_no_hazard() {
    let mut st = State::default();
    let transition = Dep {
        src: earlier(S::COLOR_ATTACHMENT_OUTPUT),
        src_access: A::COLOR_ATTACHMENT_WRITE,
        dst: later(S::FRAGMENT_SHADER),
        dst_visible: S::FRAGMENT_SHADER,
        dst_access: A::SHADER_READ.expand(),
    };
    st.transition(
        &transition,
        Access::event(&Origin::none("barrier"), What::Text("transition")),
        0,
        0,
    );
    let vertex = acc(S::VERTEX_SHADER, A::SHADER_SAMPLED_READ);
    // Straight after the transition, a vertex read is not in its second scope.
    assert!(st.clone().read(vertex.clone(), 0).is_some());
    assert!(
        st.read(acc(S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ), 0)
            .is_none()
    );
    let other_image = Dep {
        src: earlier(S::COLOR_ATTACHMENT_OUTPUT),
        src_access: A::COLOR_ATTACHMENT_WRITE,
        dst: later(S::VERTEX_SHADER),
        dst_visible: S::VERTEX_SHADER,
        dst_access: A::SHADER_READ.expand(),
    };
    // Without the barrier the vertex read is not ordered after the fragment read.
    assert!(st.clone().read(vertex.clone(), 0).is_some());
    let mut states = chains::States::default();
    let key = Key::Image {
        image: 1,
        mip: 0,
        layer: 0,
    };
    states.insert(key, st);
    states.order_all_but(&[], &other_image);
    assert!(states.entry(key).read(vertex, 0).is_none());
}

/// mpv's gpu-next renderer waits on a fence of an earlier submission after acquiring the next
/// swapchain image: that wait retires the queue's accesses, not the presentation engine's read
/// of the acquired image, which only the acquire's semaphore or fence orders. The layout
/// transition after it (from `TOP_OF_PIPE`, before the semaphore's wait stage) is then still a
/// write after that read, as the validation layer reports.
#[test]
fn a_host_wait_on_queue_work_does_not_retire_an_acquire() {
    let mut sync = Sync::new(true);
    let key = Key::Image {
        image: 1,
        mip: 0,
        layer: 0,
    };
    let acquire = Read {
        access: Access::event(&Origin::none("acquire"), What::Text(ACQUIRE_READ)),
        seq: 0,
        exec: S::EMPTY,
    };
    let shader = Read {
        access: acc(S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ),
        seq: 0,
        exec: S::EMPTY,
    };
    sync.states.insert(
        key,
        State {
            reads: vec![acquire, shader],
            ..State::default()
        },
    );
    sync.retire(3);
    let st = sync.states.get(&key).unwrap();
    assert_eq!(st.reads.len(), 1);
    let transition = Dep {
        src: earlier(S::TOP_OF_PIPE),
        src_access: A::EMPTY,
        dst: later(S::COLOR_ATTACHMENT_OUTPUT),
        dst_visible: S::COLOR_ATTACHMENT_OUTPUT,
        dst_access: A::COLOR_ATTACHMENT_WRITE,
    };
    let found = sync.states.get_mut(&key).unwrap().transition(
        &transition,
        Access::event(&Origin::none("barrier"), What::Text("transition")),
        1,
        0,
    );
    assert_eq!(
        found.iter().map(|h| h.0).collect::<Vec<_>>(),
        [HazardKind::WriteAfterRead]
    );
}

/// Qt's `QVulkanWindow` acquires with a semaphore and a fence and waits on the semaphore
/// only: the acquire is ordered (at the semaphore's wait stage), so a write racing it is a
/// write after the acquire's read, as the validation layer reports; a write after an acquire
/// nothing waited on is one after the image's last present. A new acquire starts over.
#[test]
fn an_acquire_whose_semaphore_is_waited_on_is_no_longer_the_last_present() {
    let key = Key::Image {
        image: 1,
        mip: 0,
        layer: 0,
    };
    let acquire = Access::event(&Origin::none("acquire"), What::Text(ACQUIRE_READ));
    let kind = |sync: &Sync| {
        sync.unwaited_acquire(key, HazardKind::WriteAfterRead, acquire.clone())
            .0
    };
    let mut sync = Sync::new(true);
    sync.acquire_semaphores.insert(5, vec![key]);
    sync.acquire_fences.insert(6, vec![key]);
    assert_eq!(kind(&sync), HazardKind::WriteAfterPresent);
    sync.semaphore_wait(5, S::COLOR_ATTACHMENT_OUTPUT, None);
    assert!(
        sync.acquire_fences.contains_key(&6),
        "the fence is still to be waited on"
    );
    assert_eq!(kind(&sync), HazardKind::WriteAfterRead);
    let mut by_fence = Sync::new(true);
    by_fence.acquire_fences.insert(6, vec![key]);
    by_fence.host_wait(&[6], &[], true);
    by_fence.acquire_semaphores.insert(7, vec![key]);
    assert_eq!(kind(&by_fence), HazardKind::WriteAfterRead);
}

/// FFmpeg's filters: a compute write in one submission, then a submission that waits on the
/// timeline semaphore the first signalled, at `TOP_OF_PIPE` (in a second scope: all
/// commands), and transitions the image from `TOP_OF_PIPE`. Everything the waiting batch
/// records follows the wait, its layout transitions included, so the transition is ordered
/// after the write; without the wait it is a write after write.
#[test]
fn a_timeline_wait_orders_the_layout_transitions_after_it() {
    let transition_after = |wait: bool| {
        let mut sync = Sync::new(true);
        let key = Key::Image {
            image: 1,
            mip: 0,
            layer: 0,
        };
        let mut st = State::default();
        st.write(acc(S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE), 1, 7);
        sync.states.insert(key, st);
        sync.signalled.insert(9, vec![(Some(2), 1)]);
        if wait {
            sync.semaphore_wait(9, S::TOP_OF_PIPE, Some(2));
        }
        let from_top = Dep {
            src: earlier(S::TOP_OF_PIPE),
            src_access: A::EMPTY,
            dst: later(S::TRANSFER),
            dst_visible: S::TRANSFER,
            dst_access: A::TRANSFER_READ,
        };
        let transition = Access::event(&Origin::none("barrier"), What::Text("transition"));
        let st = sync.states.get_mut(&key).unwrap();
        st.transition(&from_top, transition, 2, 7)
            .iter()
            .map(|h| h.0)
            .collect::<Vec<_>>()
    };
    assert!(transition_after(true).is_empty());
    assert_eq!(transition_after(false), [HazardKind::WriteAfterWrite]);
}

fn call(name: &'static str, index: u64) -> Origin {
    Origin::call(&Cow::Borrowed(name), index)
}

#[test]
fn a_layout_set_outside_the_command_buffer_is_judged_at_its_submission() {
    use ImageLayout as L;
    let mut sync = Sync::new(true);
    let key = Key::Image {
        image: 7,
        mip: 0,
        layer: 0,
    };
    let sampled = |at: u64| {
        (
            call("vkCmdDraw", at),
            What::InLayout("descriptor in", L::ShaderReadOnlyOptimal),
        )
    };
    sync.start_layout(7, L::Undefined, call("vkCreateImage", 3));
    sync.submission = Some(call("vkQueueSubmit", 30));
    sync.walking = 11;
    // Never transitioned since its creation: the command buffer's expectation is the
    // submission's finding, naming the draw that expects it.
    let (draw, what) = sampled(20);
    sync.expect_layout(key, L::ShaderReadOnlyOptimal, &draw, what);
    // Put in another layout by a command of the same command buffer: the command's own.
    sync.set_layout(
        key,
        L::TransferDstOptimal,
        &call("vkCmdPipelineBarrier", 21),
    );
    let (draw, what) = sampled(22);
    sync.expect_layout(key, L::ShaderReadOnlyOptimal, &draw, what);
    // In the layout it is used in: nothing.
    sync.set_layout(
        key,
        L::ShaderReadOnlyOptimal,
        &call("vkCmdPipelineBarrier", 23),
    );
    let (draw, what) = sampled(24);
    sync.expect_layout(key, L::ShaderReadOnlyOptimal, &draw, what);
    let (found, _) = sync.hazards(|_| Some("image_7".to_owned()));
    let found: Vec<(String, String, String, String)> = found
        .into_iter()
        .map(|(_, h)| (h.command, h.access, h.prior, h.prior_command))
        .collect();
    assert_eq!(
        found,
        [
            (
                "vkCmdDraw #22".to_owned(),
                "descriptor in SHADER_READ_ONLY_OPTIMAL".to_owned(),
                "layout TRANSFER_DST_OPTIMAL".to_owned(),
                "vkCmdPipelineBarrier #21".to_owned()
            ),
            (
                "vkQueueSubmit #30".to_owned(),
                "descriptor in SHADER_READ_ONLY_OPTIMAL at vkCmdDraw #20".to_owned(),
                "layout UNDEFINED".to_owned(),
                "vkCreateImage #3".to_owned()
            ),
        ]
    );
}

#[test]
fn disjoint_ranges_of_one_buffer_need_no_dependency() {
    let mut sync = Sync::new(true);
    let mut objects = Objects::default();
    objects.buffers.insert(
        9,
        crate::import::state::BufferInfo {
            created_at: 0,
            destroyed_at: None,
            size: 1024,
            usage: 0,
            bound: None,
            alignment: None,
        },
    );
    let write = |at: u64| Access {
        command: call("vkCmdCopyBuffer", at),
        ..acc(S::COPY, A::TRANSFER_WRITE)
    };
    let read = |at: u64| Access {
        command: call("vkCmdDraw", at),
        ..acc(S::VERTEX_INPUT, A::VERTEX_ATTRIBUTE_READ)
    };
    // A copy into the second half, then a draw reading the first half: no hazard.
    let second = sync.buffer_keys(&objects, 9, (512, 512));
    sync.access(&second, true, &write(1));
    let first = sync.buffer_keys(&objects, 9, (0, 512));
    sync.access(&first, false, &read(2));
    assert!(sync.hazards(|_| None).0.is_empty());
    // A read of bytes 256.. reaches into the written half: a read after write, and the range
    // it split keeps the write it came from.
    let across = sync.buffer_keys(&objects, 9, (256, u64::MAX));
    assert_eq!(across.len(), 2, "{across:?}");
    sync.access(&across, false, &read(3));
    let found: Vec<(String, HazardKind)> = sync
        .hazards(|_| None)
        .0
        .into_iter()
        .map(|(_, h)| (h.command, h.kind))
        .collect();
    assert_eq!(
        found,
        [("vkCmdDraw #3".to_owned(), HazardKind::ReadAfterWrite)]
    );
    // Split at 768 by a barrier-sized range: both halves still hold the write.
    let tail = sync.buffer_keys(&objects, 9, (768, 256));
    assert_eq!(
        tail,
        [Key::Buffer {
            buffer: 9,
            start: 768
        }]
    );
    assert!(sync.states.get(&tail[0]).unwrap().write.is_some());
    assert!(
        sync.states
            .get(&Key::Buffer {
                buffer: 9,
                start: 512
            })
            .unwrap()
            .write
            .is_some()
    );
}

#[test]
fn a_barrier_from_a_layout_to_itself_transitions_only_without_synchronization2() {
    use ImageLayout as L;
    let key = Key::Image {
        image: 5,
        mip: 0,
        layer: 0,
    };
    let same = BarrierCmd {
        origin: call("vkCmdPipelineBarrier2", 40),
        target: BarrierTarget::Image {
            image: 5,
            mips: (0, None),
            layers: (0, None),
        },
        src_stages: S::LATE_FRAGMENT_TESTS,
        dst_stages: S::EARLY_FRAGMENT_TESTS,
        src_access: A::DEPTH_STENCIL_ATTACHMENT_WRITE,
        dst_access: A::DEPTH_STENCIL_ATTACHMENT_READ,
        layouts: Some((
            L::DepthStencilAttachmentOptimal,
            L::DepthStencilAttachmentOptimal,
        )),
        families: None,
    };
    for sync2 in [true, false] {
        let objects = Objects {
            synchronization2: sync2,
            ..Objects::default()
        };
        let mut sync = Sync::new(true);
        sync.start_layout(5, L::Undefined, call("vkCreateImage", 3));
        sync.submission = Some(call("vkQueueSubmit", 50));
        sync.walking = 1;
        sync.barrier(&objects, &same, true);
        let found = sync.hazards(|_| None).0.len();
        if sync2 {
            // Its layouts are ignored: nothing found, and the image is still where it was.
            assert_eq!(found, 0);
            assert!(sync.states.get(&key).is_none_or(|s| s.layout.is_none()));
        } else {
            // A transition whose old layout is not the image's.
            assert_eq!(found, 1);
        }
    }
}
