//! GPU plumbing for wgpu techniques (DESIGN section 2), behind the `gpu` feature.
//!
//! * [`GpuContext::new`] picks an adapter from the environment: `WGPU_BACKEND` (a comma list
//!   such as `vulkan,gl`) restricts the backends, `WGPU_ADAPTER_NAME` selects by a
//!   case-insensitive part of the name; otherwise the best kind wins (discrete, integrated,
//!   virtual, other, then the CPU/software adapter such as Mesa's lavapipe). The device asks for
//!   the adapter's own limits, and [`GpuContext::limits`] reports them so callers split work
//!   that would exceed them.
//! * [`GpuContext::shared`] hands out one context per process, created on first use.
//! * Upload ([`GpuContext::storage`], [`GpuContext::uniform`]) and readback
//!   ([`GpuContext::read`]) helpers, a 2D split of large dispatches ([`GpuContext::grid`]).
//! * [`validate_wgsl`] parses and validates WGSL with `naga`, with no device, so every shader
//!   is checked by plain tests; [`GpuContext::pipeline`] validates before it compiles.
//! * Device errors are caught (never a panic): every submission is followed by a check of the
//!   errors the device reported, returned as [`GpuError::Device`].
//! * [`gpu_required`]: `SHADOW_REQUIRE_GPU` set to anything but `0` or empty makes a missing
//!   adapter an error instead of a loudly reported skip (CI sets it).

use std::sync::{Arc, Mutex, OnceLock};

use bytemuck::Pod;
use thiserror::Error;
use wgpu::util::DeviceExt;

pub use crate::gpu_timestamps::Encoder;

/// Environment variable that turns a missing adapter into a failure.
pub const REQUIRE_GPU_ENV: &str = "SHADOW_REQUIRE_GPU";

/// True when the environment asks for a real adapter (`SHADOW_REQUIRE_GPU` set, not `0`).
pub fn gpu_required() -> bool {
    std::env::var(REQUIRE_GPU_ENV).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// Why a GPU operation failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GpuError {
    /// No adapter matches the environment (or none exists).
    #[error("no GPU adapter: {0}")]
    NoAdapter(String),
    /// The device could not be created or reported an error.
    #[error("GPU device: {0}")]
    Device(String),
    /// A WGSL module failed naga's parser or validator.
    #[error("WGSL module `{module}`: {message}")]
    Shader {
        /// Module label.
        module: String,
        /// naga's message.
        message: String,
    },
    /// Data the caller should have split exceeds a device limit.
    #[error("{what} needs {needed} bytes, above the device limit of {limit}")]
    TooLarge {
        /// What was too large.
        what: String,
        /// Bytes needed.
        needed: u64,
        /// The limit.
        limit: u64,
    },
    /// A value about to be uploaded is NaN or infinite.
    #[error("{0} holds a NaN or infinite value; nothing non-finite reaches a shader")]
    NonFinite(String),
}

/// A device, its queue, and what its adapter is.
pub struct GpuContext {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    errors: Arc<Mutex<Vec<String>>>,
    exclusive: Mutex<()>,
    /// Nanoseconds per timestamp tick, where the device has timestamp queries.
    timestamp_period: Option<f32>,
    /// Device seconds of the timed passes submitted since the last take; `None` once an
    /// untimed pass was among them.
    device_seconds: Mutex<Option<f64>>,
}

impl std::fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuContext")
            .field("adapter", &self.describe())
            .finish_non_exhaustive()
    }
}

fn kind_rank(t: wgpu::DeviceType) -> u32 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// Picks an adapter: by `name` (case-insensitive substring) when given, else the best kind.
fn choose(adapters: Vec<wgpu::Adapter>, name: Option<&str>) -> Result<wgpu::Adapter, GpuError> {
    let names: Vec<String> = adapters
        .iter()
        .map(|a| {
            let i = a.get_info();
            format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type)
        })
        .collect();
    if adapters.is_empty() {
        return Err(GpuError::NoAdapter(
            "no adapter on any enabled backend (WGPU_BACKEND); on Linux `apt-get install \
             mesa-vulkan-drivers` provides the software Vulkan adapter lavapipe"
                .into(),
        ));
    }
    match name {
        Some(want) => {
            let want = want.to_lowercase();
            adapters
                .into_iter()
                .find(|a| a.get_info().name.to_lowercase().contains(&want))
                .ok_or_else(|| {
                    GpuError::NoAdapter(format!(
                        "WGPU_ADAPTER_NAME=`{want}` matches none of: {}",
                        names.join(", ")
                    ))
                })
        }
        None => Ok(adapters
            .into_iter()
            .min_by_key(|a| kind_rank(a.get_info().device_type))
            .expect("not empty")),
    }
}

impl GpuContext {
    /// Creates a device on the adapter the environment selects (see the module docs).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] when no adapter matches; [`GpuError::Device`] when the device
    /// cannot be created.
    pub fn new() -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
        let adapters = pollster::block_on(instance.enumerate_adapters(backends));
        let name = std::env::var("WGPU_ADAPTER_NAME")
            .ok()
            .filter(|s| !s.is_empty());
        let adapter = choose(adapters, name.as_deref())?;
        let limits = adapter.limits();
        let timestamps = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("shadow-core"),
            required_features: timestamps,
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        let timestamp_period = (!timestamps.is_empty()).then(|| queue.get_timestamp_period());
        Ok(Self {
            device,
            queue,
            info: adapter.get_info(),
            limits,
            errors,
            exclusive: Mutex::new(()),
            timestamp_period,
            device_seconds: Mutex::new(Some(0.0)),
        })
    }

    /// The process-wide context, created on first use (the result, error included, is kept).
    ///
    /// # Errors
    /// As [`GpuContext::new`].
    pub fn shared() -> Result<Arc<GpuContext>, GpuError> {
        static SHARED: OnceLock<Result<Arc<GpuContext>, GpuError>> = OnceLock::new();
        SHARED
            .get_or_init(|| GpuContext::new().map(Arc::new))
            .clone()
    }

    /// Serialises a multi-submission job against other threads sharing the context (a
    /// poisoned lock is recovered: the guard protects no data).
    pub fn exclusive(&self) -> std::sync::MutexGuard<'_, ()> {
        self.exclusive.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The device.
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }
    /// The queue.
    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }
    /// The adapter's description.
    pub fn info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }
    /// The device's limits (the adapter's own).
    pub fn limits(&self) -> &wgpu::Limits {
        &self.limits
    }
    /// True for a CPU (software) adapter.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// One line naming the adapter, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)`.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}, driver {})",
            self.info.name, self.info.backend, self.info.device_type, self.info.driver_info
        )
    }

    /// Largest storage binding in bytes.
    pub fn max_binding(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    /// Fails when `bytes` exceed the storage binding limit.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`].
    pub fn check_binding(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        if bytes > self.max_binding() {
            return Err(GpuError::TooLarge {
                what: what.into(),
                needed: bytes,
                limit: self.max_binding(),
            });
        }
        Ok(())
    }

    /// A storage buffer holding `data` (at least 16 bytes, zero-padded), readable and writable
    /// by shaders and copyable both ways.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] above the binding limit.
    pub fn storage<T: Pod>(&self, label: &str, data: &[T]) -> Result<wgpu::Buffer, GpuError> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        self.check_binding(label, bytes.len() as u64)?;
        if bytes.len() >= 16 {
            Ok(self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage: storage_usage(),
                }))
        } else {
            let mut padded = vec![0u8; 16];
            padded[..bytes.len()].copy_from_slice(bytes);
            Ok(self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: &padded,
                    usage: storage_usage(),
                }))
        }
    }

    /// A zero-filled storage buffer of `bytes` bytes (at least 16).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] above the binding limit.
    pub fn storage_zeroed(&self, label: &str, bytes: u64) -> Result<wgpu::Buffer, GpuError> {
        self.check_binding(label, bytes)?;
        Ok(self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16).next_multiple_of(4),
            usage: storage_usage(),
            mapped_at_creation: false,
        }))
    }

    /// A uniform buffer holding `value`.
    pub fn uniform<T: Pod>(&self, label: &str, value: &T) -> wgpu::Buffer {
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::bytes_of(value),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
    }

    /// Reads `count` values of type `T` back from the start of `buffer` (waits for the GPU).
    ///
    /// # Errors
    /// [`GpuError::Device`] when the copy or the mapping fails, or the device reported an
    /// error since the last check.
    pub fn read<T: Pod>(&self, buffer: &wgpu::Buffer, count: usize) -> Result<Vec<T>, GpuError> {
        let bytes = (count * std::mem::size_of::<T>()) as u64;
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let size = bytes.next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
        if size > buffer.size() {
            return Err(GpuError::Device(format!(
                "read of {size} bytes from a buffer of {}",
                buffer.size()
            )));
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        let slot = Arc::new(Mutex::new(None));
        let s2 = slot.clone();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            if let Ok(mut g) = s2.lock() {
                *g = Some(r);
            }
        });
        // The callback runs inside whichever thread polls; poll until it has run.
        for _ in 0..10_000 {
            self.wait()?;
            if slot.lock().map(|g| g.is_some()).unwrap_or(true) {
                break;
            }
            std::thread::yield_now();
        }
        match slot.lock().map(|mut g| g.take()) {
            Ok(Some(Ok(()))) => {}
            Ok(Some(Err(e))) => return Err(GpuError::Device(format!("map failed: {e}"))),
            _ => return Err(GpuError::Device("map callback never ran".into())),
        }
        let view = staging
            .get_mapped_range(..)
            .map_err(|e| GpuError::Device(format!("mapped range: {e:?}")))?;
        let out = bytemuck::cast_slice::<u8, T>(&view[..bytes as usize]).to_vec();
        drop(view);
        staging.unmap();
        Ok(out)
    }

    /// Blocks until every submitted command finished, then reports any device error.
    ///
    /// # Errors
    /// [`GpuError::Device`] on a failed poll or a reported validation or memory error.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: None,
            })
            .map_err(|e| GpuError::Device(e.to_string()))?;
        self.check_errors()
    }

    /// Returns (and clears) the errors the device reported since the last check.
    ///
    /// # Errors
    /// [`GpuError::Device`] with every message.
    pub fn check_errors(&self) -> Result<(), GpuError> {
        let mut v = self
            .errors
            .lock()
            .map_err(|_| GpuError::Device("error sink poisoned".into()))?;
        if v.is_empty() {
            Ok(())
        } else {
            let msg = v.join("; ");
            v.clear();
            Err(GpuError::Device(msg))
        }
    }

    /// A compute pipeline for entry point `entry` of WGSL `source`, validated by naga first
    /// (bind group layouts are derived from the shader).
    ///
    /// # Errors
    /// [`GpuError::Shader`] when naga rejects the module; [`GpuError::Device`] when the device
    /// does.
    pub fn pipeline(
        &self,
        label: &str,
        source: &str,
        entry: &str,
    ) -> Result<wgpu::ComputePipeline, GpuError> {
        validate_wgsl(source).map_err(|message| GpuError::Shader {
            module: label.into(),
            message,
        })?;
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
        let p = self
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: None,
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            });
        self.check_errors()?;
        Ok(p)
    }

    /// A bind group for group 0 of `pipeline` with `buffers` bound at bindings 0, 1, ...
    pub fn bind(
        &self,
        pipeline: &wgpu::ComputePipeline,
        buffers: &[&wgpu::Buffer],
    ) -> wgpu::BindGroup {
        let layout = pipeline.get_bind_group_layout(0);
        let entries: Vec<wgpu::BindGroupEntry<'_>> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &layout,
            entries: &entries,
        })
    }

    /// Workgroup grid `(x, y)` covering `groups` workgroups within the per-dimension dispatch
    /// limit (shaders rebuild the linear index as `y * x_count + x` and skip indices past the
    /// end).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when even a square grid exceeds the limit.
    pub fn grid(&self, groups: u64) -> Result<(u32, u32), GpuError> {
        let max = self.limits.max_compute_workgroups_per_dimension.max(1) as u64;
        if groups <= max {
            return Ok((groups.max(1) as u32, 1));
        }
        let y = groups.div_ceil(max);
        if y > max {
            return Err(GpuError::TooLarge {
                what: "dispatch".into(),
                needed: groups,
                limit: max * max,
            });
        }
        Ok((groups.div_ceil(y) as u32, y as u32))
    }

    /// Records a dispatch of `pipeline` over `groups` workgroups (split by [`GpuContext::grid`])
    /// into `enc`.
    ///
    /// # Errors
    /// As [`GpuContext::grid`].
    pub fn dispatch(
        &self,
        enc: &mut Encoder,
        pipeline: &wgpu::ComputePipeline,
        bind: &wgpu::BindGroup,
        groups: u64,
    ) -> Result<(), GpuError> {
        if groups == 0 {
            return Ok(());
        }
        let (x, y) = self.grid(groups)?;
        let Encoder { inner, queries } = enc;
        let timestamp_writes = queries.as_mut().and_then(|q| q.next_pass());
        let mut pass = inner.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: None,
            timestamp_writes,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(x, y, 1);
        Ok(())
    }

    /// Submits `enc` and waits for it (per-phase timing submits each phase on its own). With
    /// timestamp queries, the device time of its passes is read back and added to
    /// [`GpuContext::take_device_seconds`]'s total.
    ///
    /// # Errors
    /// As [`GpuContext::wait`] and [`GpuContext::read`].
    pub fn submit(&self, enc: Encoder) -> Result<(), GpuError> {
        let Encoder { mut inner, queries } = enc;
        let timed = match queries {
            Some(q) if q.used > 0 => {
                let bytes = q.used as u64 * 8;
                let resolve = self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamps"),
                    size: bytes,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                inner.resolve_query_set(&q.set, 0..q.used, &resolve, 0);
                Some((resolve, q.used, q.untimed))
            }
            Some(q) => {
                if q.untimed {
                    self.add_device_seconds(None);
                }
                None
            }
            None => None,
        };
        self.queue.submit([inner.finish()]);
        self.wait()?;
        if let (Some((resolve, used, untimed)), Some(period)) = (timed, self.timestamp_period) {
            let ticks: Vec<u64> = self.read(&resolve, used as usize)?;
            let s = crate::gpu_timestamps::pass_seconds(&ticks, period);
            self.add_device_seconds((!untimed).then_some(s));
        }
        Ok(())
    }

    fn add_device_seconds(&self, s: Option<f64>) {
        let mut total = self
            .device_seconds
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        *total = match (*total, s) {
            (Some(t), Some(s)) => Some(t + s),
            _ => None,
        };
    }

    /// Whether the device has timestamp queries (so [`GpuContext::take_device_seconds`]
    /// reports device time).
    pub fn has_timestamps(&self) -> bool {
        self.timestamp_period.is_some()
    }

    /// The device time (seconds, from timestamp queries) of the compute passes submitted
    /// since the last call, and starts a new total. `None` without timestamp queries, or when
    /// some pass since the last call ran untimed (an encoder past its query capacity).
    pub fn take_device_seconds(&self) -> Option<f64> {
        let mut total = self
            .device_seconds
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let out = if self.has_timestamps() { *total } else { None };
        *total = Some(0.0);
        out
    }

    /// A new command encoder, with a query set for its passes' timestamps where the device
    /// has them.
    pub fn encoder(&self) -> Encoder {
        let queries = self
            .timestamp_period
            .map(|_| crate::gpu_timestamps::Queries {
                set: self.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: crate::gpu_timestamps::CAPACITY,
                }),
                used: 0,
                untimed: false,
            });
        Encoder {
            inner: self.device.create_command_encoder(&Default::default()),
            queries,
        }
    }
}

/// The shared context for a test, printing the adapter; `None` (reported loudly on stderr)
/// when there is no adapter, unless [`gpu_required`], in which case it panics: a GPU test run
/// by CI fails when no adapter is found.
///
/// # Panics
/// When no adapter is found and `SHADOW_REQUIRE_GPU` is set.
pub fn context_for_test(test: &str) -> Option<Arc<GpuContext>> {
    match GpuContext::shared() {
        Ok(g) => {
            println!("{test}: GPU adapter {}", g.describe());
            Some(g)
        }
        Err(e) if gpu_required() => panic!("{test}: {REQUIRE_GPU_ENV} is set but {e}"),
        Err(e) => {
            eprintln!("SKIPPED {test}: {e} (set {REQUIRE_GPU_ENV}=1 to make this a failure)");
            None
        }
    }
}

fn storage_usage() -> wgpu::BufferUsages {
    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST
}

/// Parses and validates a WGSL module with naga (no device needed).
///
/// # Errors
/// naga's message, with the source location.
pub fn validate_wgsl(source: &str) -> Result<naga::Module, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map_err(|e| e.emit_to_string(source))?;
    Ok(module)
}

/// Fails when any value is NaN or infinite.
///
/// # Errors
/// [`GpuError::NonFinite`] naming `what`.
pub fn check_finite(values: &[f32], what: &str) -> Result<(), GpuError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(GpuError::NonFinite(what.into()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn naga_rejects_broken_wgsl_and_accepts_good() {
        let good = "@group(0) @binding(0) var<storage, read_write> a: array<u32>;\n\
                    @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) g: vec3<u32>) {\n\
                      if g.x < arrayLength(&a) { a[g.x] = a[g.x] * 2u; }\n}\n";
        assert!(validate_wgsl(good).is_ok());
        let bad = good.replace("2u", "2.0");
        let e = validate_wgsl(&bad).unwrap_err();
        assert!(!e.is_empty());
    }

    #[test]
    fn non_finite_values_are_refused() {
        assert!(check_finite(&[1.0, 2.0], "x").is_ok());
        assert_eq!(
            check_finite(&[1.0, f32::NAN], "positions"),
            Err(GpuError::NonFinite("positions".into()))
        );
    }

    #[test]
    fn a_dispatch_doubles_a_buffer_on_the_adapter() {
        let Some(gpu) = context_for_test("a_dispatch_doubles_a_buffer_on_the_adapter") else {
            return;
        };
        let src = "@group(0) @binding(0) var<storage, read_write> a: array<u32>;\n\
                   @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {\n\
                     let i = g.y * n.x * 64u + g.x;\n\
                     if i < arrayLength(&a) { a[i] = a[i] * 2u + 1u; }\n}\n";
        let p = gpu.pipeline("double", src, "main").unwrap();
        let data: Vec<u32> = (0..1000).collect();
        let buf = gpu.storage("data", &data).unwrap();
        let bind = gpu.bind(&p, &[&buf]);
        let mut enc = gpu.encoder();
        gpu.dispatch(&mut enc, &p, &bind, 1000u64.div_ceil(64))
            .unwrap();
        gpu.submit(enc).unwrap();
        let out: Vec<u32> = gpu.read(&buf, 1000).unwrap();
        assert!(out.iter().enumerate().all(|(i, v)| *v == 2 * i as u32 + 1));
        // A 2D split covers exactly the groups asked for.
        let (x, y) = gpu.grid(10_000_000).unwrap();
        assert!(x as u64 * y as u64 >= 10_000_000);
        assert!(x <= gpu.limits().max_compute_workgroups_per_dimension);
    }
}
