// SPDX-License-Identifier: Apache-2.0
// C# bindings of libpose and libpose_bridge (pose/pose.h, pose/bridge.h):
// P/Invoke declarations and SafeHandle wrappers. One file, C# 6 and the
// .NET Framework 4 profile only (no Span, no unsafe code, no NativeLibrary),
// so it compiles as-is in Unity (copy it under Assets/ beside the native
// libpose / libpose_bridge plug-ins) and with Debian's mcs.
//
//     using (var rig = new Pose.Rig("patient.rig"))
//     using (var state = new Pose.State(rig, 0, Pose.Method.DQS)) {
//         state.SetJointEuler(rig.FindJoint("knee_r"), 0, 90, 0);
//         state.Apply();
//         float[] skin = state.Positions(0);   // x0 y0 z0 x1 ...
//     }
//
// Failures throw PoseException carrying pose_last_error(). Struct layouts are
// those of 64-bit Linux and macOS (C `long` is 64 bits: BridgeOptions.MaxPoses,
// BridgeStatus.Frame/FrameCount).
using System;
using System.Collections.Generic;
using System.Runtime.InteropServices;

namespace Pose
{
    public enum Status { OK = 0, Clamped = 1, InvalidArgument = -1, OutOfMemory = -2, IO = -3, Format = -4,
                         Version = -5, Checksum = -6, InvalidData = -7, Unsupported = -8, NotFound = -9,
                         Thread = -10 }
    public enum Method { LBS = 0, DQS = 1, COR = 2, FEM = 3 }
    public enum EulerOrder { XYZ = 0, XZY = 1, YXZ = 2, YZX = 3, ZXY = 4, ZYX = 5 }
    public enum TissueKind { Skin = 0, Bone = 1, Muscle = 2, Organ = 3, Other = 4 }
    public enum Play { Realtime = 0, AsFastAsPossible = 1, Manual = 2 }

    public class PoseException : Exception
    {
        public readonly Status Status;
        public PoseException(Status status, string message) : base(status + ": " + message) { Status = status; }
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct Allocator { public IntPtr Alloc, Free, User; }

    [StructLayout(LayoutKind.Sequential)]
    public struct LoadOptions { public UIntPtr Size; public Allocator Allocator; public uint Flags; }

    [StructLayout(LayoutKind.Sequential)]
    public struct StateOptions { public UIntPtr Size; public Allocator Allocator; public int Threads; public Method Method; }

    /// <summary>pose_dynamics_options: start from DynamicsOptions.Defaults().</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct DynamicsOptions
    {
        public UIntPtr Size;
        public float MassDamping, StiffnessDamping;
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public float[] Gravity;
        public float CouplingStiffness, Tolerance;
        public int CgIterations;

        public static DynamicsOptions Defaults()
        {
            var o = new DynamicsOptions { Gravity = new float[3] };
            Native.pose_dynamics_defaults(ref o);
            return o;
        }
    }

    /// <summary>pose_dynamics_stats: what the last State.Step did.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct DynamicsStats
    {
        public UIntPtr Size;
        public int Islands, CgIterations;
        public double Residual, KineticEnergy, Time;
        public double SecondsSkin, SecondsAssembly, SecondsCg, SecondsTransfer;
        public int Contacts, ContactIterations; // the contact response in pose_step (pose/contact.h)
        public double MaxImpulse, SecondsContact;
    }

    /// <summary>pose_fem_coupling: a simulation node tied to a joint's bone by a zero-length spring.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct FemCoupling
    {
        public uint Node;        // tet vertex index (State.TetPositions)
        public int Joint;
        public float Stiffness;  // multiple of the node's own elastic stiffness, > 0 (pose-bake's default 100)
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public float[] Anchor; // the bone end at rest, model space
    }

    /// <summary>pose_fem_soft_coupling: a simulation node tied by a zero-length spring to the point
    /// sum(Weight[c] * x[Other[c]]) of up to 4 other nodes (a node pair: Other {b}, Weight {1}).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct FemSoftCoupling
    {
        public uint Node;
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 4)] public uint[] Other;
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 4)] public float[] Weight; // summing to 1; 0: unused
        public float Stiffness;  // multiple of the node's own elastic stiffness, > 0

        public static FemSoftCoupling Pair(uint node, uint other, float stiffness)
        {
            return new FemSoftCoupling { Node = node, Other = new uint[] { other, 0, 0, 0 },
                                         Weight = new float[] { 1, 0, 0, 0 }, Stiffness = stiffness };
        }
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct Transform
    {
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 4)] public float[] Rotation;    // x y z w
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public float[] Translation;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct JointInfo
    {
        public IntPtr NamePtr;
        public int Parent;
        public Transform RestModel, RestLocal;
        public uint LimitFlags;
        public EulerOrder LimitOrder;
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public float[] LimitMinDeg;
        [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public float[] LimitMaxDeg;
        public string Name { get { return Marshal.PtrToStringAnsi(NamePtr); } }
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct TissueInfo
    {
        public IntPtr NamePtr;
        public TissueKind Kind;
        public int Joint;
        public UIntPtr VertexCount, TriangleCount;
        public IntPtr RestPositions, Triangles;
        public string Name { get { return Marshal.PtrToStringAnsi(NamePtr); } }
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct BridgeOptions
    {
        public UIntPtr Size;
        [MarshalAs(UnmanagedType.LPStr)] public string MapPath;
        [MarshalAs(UnmanagedType.LPStr)] public string MapJson;
        [MarshalAs(UnmanagedType.LPStr)] public string Skeleton;
        public Play Play;
        public double Speed;
        public int Loop;
        public double StartS, EndS;
        public long MaxPoses;
        public int StartPaused;
        public double RateHz, StaleAfterS;
        public int RtPriority;
        [MarshalAs(UnmanagedType.LPStr)] public string RecordPath;
        public Allocator Allocator;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct BridgeFrame
    {
        public int Fresh, Held, Clamped, Joints;
        public double MediaS, AgeS;
        public ulong Seq;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct BridgeStatus
    {
        public UIntPtr Size;
        public int State, Connected;
        public IntPtr KindPtr;
        public ulong Samples, Drops, Poses;
        public double LastSampleAgeS, MediaS, DurationS, LagP50Ms, LagP99Ms, LagMaxMs;
        public int Realtime;
        public long Frame, FrameCount;
        public double FrameTimeS;
        [MarshalAs(UnmanagedType.ByValTStr, SizeConst = 256)] public string Fault;
        public string Kind { get { return Marshal.PtrToStringAnsi(KindPtr); } }
    }

    /// <summary>The C functions, as exported. The options-taking ones are the *_sized symbols (pose.h's ABI note).</summary>
    public static class Native
    {
        const string Lib = "pose", Bridge = "pose_bridge";
        [DllImport(Lib)] public static extern IntPtr pose_version_string();
        [DllImport(Lib)] public static extern IntPtr pose_last_error();
        [DllImport(Lib)] public static extern uint pose_rig_format_version(IntPtr rig);
        [DllImport(Lib)] public static extern Status pose_rig_load_ex_sized(string path, ref LoadOptions options, out IntPtr rig);
        [DllImport(Lib)] public static extern void pose_rig_free(IntPtr rig);
        [DllImport(Lib)] public static extern UIntPtr pose_rig_joint_count(RigHandle rig);
        [DllImport(Lib)] public static extern int pose_rig_find_joint(RigHandle rig, string name);
        [DllImport(Lib)] public static extern Status pose_rig_joint_info(RigHandle rig, int joint, out JointInfo info);
        [DllImport(Lib)] public static extern UIntPtr pose_rig_tissue_count(RigHandle rig);
        [DllImport(Lib)] public static extern int pose_rig_find_tissue(RigHandle rig, string name);
        [DllImport(Lib)] public static extern Status pose_rig_tissue_info(RigHandle rig, int tissue, out TissueInfo info);
        [DllImport(Lib)] public static extern Status pose_rig_bounds(RigHandle rig, int tissue, float[] min, float[] max);
        [DllImport(Lib)] public static extern Status pose_state_create_ex_sized(RigHandle rig, ref StateOptions options, out IntPtr state);
        [DllImport(Lib)] public static extern void pose_state_free(IntPtr state);
        [DllImport(Lib)] public static extern Status pose_set_joint(StateHandle state, int joint, float[] quatXyzw);
        [DllImport(Lib)] public static extern Status pose_set_joint_euler(StateHandle state, int joint, float[] deg, EulerOrder order);
        [DllImport(Lib)] public static extern Status pose_set_joint_clinical(StateHandle state, int joint, float[] deg);
        [DllImport(Lib)] public static extern Status pose_get_joint_clinical(StateHandle state, int joint, float[] deg);
        [DllImport(Lib)] public static extern Status pose_set_neutral(StateHandle state);
        [DllImport(Lib)] public static extern Status pose_reset(StateHandle state);
        [DllImport(Lib)] public static extern Status pose_set_method(StateHandle state, Method method);
        [DllImport(Lib)] public static extern Method pose_get_method(StateHandle state);
        [DllImport(Lib)] public static extern Status pose_apply(StateHandle state);
        [DllImport(Lib)] public static extern IntPtr pose_tissue_positions(StateHandle state, int tissue, out UIntPtr count);
        [DllImport(Lib)] public static extern IntPtr pose_tissue_normals(StateHandle state, int tissue, out UIntPtr count);
        [DllImport(Lib)] public static extern Status pose_joint_world(StateHandle state, int joint, out Transform world);
        [DllImport(Lib)] public static extern Status pose_state_bounds(StateHandle state, int tissue, float[] min, float[] max);
        [DllImport(Lib)] public static extern int pose_rig_has_fem(RigHandle rig);
        [DllImport(Lib)] public static extern void pose_dynamics_defaults(ref DynamicsOptions options);
        [DllImport(Lib)] public static extern Status pose_set_dynamics_options(StateHandle state, ref DynamicsOptions options);
        [DllImport(Lib)] public static extern Status pose_step(StateHandle state, double dt);
        [DllImport(Lib)] public static extern Status pose_reset_dynamics(StateHandle state);
        [DllImport(Lib)] public static extern Status pose_get_dynamics_stats(StateHandle state, ref DynamicsStats stats);
        [DllImport(Lib)] public static extern IntPtr pose_tet_positions(StateHandle state, out UIntPtr count);
        [DllImport(Lib)] public static extern UIntPtr pose_rig_fem_couplings(RigHandle rig, [Out] FemCoupling[] couplings, UIntPtr capacity);
        [DllImport(Lib)] public static extern Status pose_rig_fem_nodes_near_joint(RigHandle rig, int joint, float reach, [Out] uint[] nodes, UIntPtr capacity, out UIntPtr count);
        [DllImport(Lib)] public static extern Status pose_set_fem_couplings(StateHandle state, FemCoupling[] couplings, UIntPtr count, UIntPtr elementSize);
        [DllImport(Lib)] public static extern UIntPtr pose_fem_coupling_count(StateHandle state);
        [DllImport(Lib)] public static extern UIntPtr pose_rig_fem_soft_couplings(RigHandle rig, [Out] FemSoftCoupling[] couplings, UIntPtr capacity, UIntPtr elementSize);
        [DllImport(Lib)] public static extern Status pose_set_fem_soft_couplings(StateHandle state, FemSoftCoupling[] couplings, UIntPtr count, UIntPtr elementSize);
        [DllImport(Lib)] public static extern UIntPtr pose_fem_soft_coupling_count(StateHandle state);
        [DllImport(Bridge)] public static extern Status pose_bridge_open(string source, RigHandle rig, ref BridgeOptions options, out IntPtr bridge);
        [DllImport(Bridge)] public static extern void pose_bridge_close(IntPtr bridge);
        [DllImport(Bridge)] public static extern Status pose_bridge_apply(BridgeHandle bridge, StateHandle state, out BridgeFrame frame);
        [DllImport(Bridge)] public static extern Status pose_bridge_pose_at(BridgeHandle bridge, double t, StateHandle state, out BridgeFrame frame);
        [DllImport(Bridge)] public static extern Status pose_bridge_status_get(BridgeHandle bridge, ref BridgeStatus status);
        [DllImport(Bridge)] public static extern IntPtr pose_bridge_state_name(int state);

        /// <summary>Throw for a failure; true when a joint limit clamped the request.</summary>
        public static bool Check(Status status)
        {
            if (status < 0)
                throw new PoseException(status, Marshal.PtrToStringAnsi(pose_last_error()));
            return status == Status.Clamped;
        }
    }

    public sealed class RigHandle : SafeHandle
    {
        public RigHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid { get { return handle == IntPtr.Zero; } }
        protected override bool ReleaseHandle() { Native.pose_rig_free(handle); return true; }
        internal void Set(IntPtr h) { SetHandle(h); }
    }

    /// <summary>A state holds a reference on its rig's handle, so the rig is freed after every state.</summary>
    public sealed class StateHandle : SafeHandle
    {
        internal RigHandle Rig;
        public StateHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid { get { return handle == IntPtr.Zero; } }
        protected override bool ReleaseHandle()
        {
            Native.pose_state_free(handle);
            Rig.DangerousRelease();
            return true;
        }
        internal void Set(IntPtr h) { SetHandle(h); }
    }

    public sealed class BridgeHandle : SafeHandle
    {
        internal RigHandle Rig;
        public BridgeHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid { get { return handle == IntPtr.Zero; } }
        protected override bool ReleaseHandle()
        {
            Native.pose_bridge_close(handle);
            Rig.DangerousRelease();
            return true;
        }
        internal void Set(IntPtr h) { SetHandle(h); }
    }

    /// <summary>A rig file, loaded and checked; immutable, shareable across threads.</summary>
    public sealed class Rig : IDisposable
    {
        public readonly RigHandle Handle = new RigHandle();

        public Rig(string path)
        {
            var options = new LoadOptions { Size = (UIntPtr)Marshal.SizeOf(typeof(LoadOptions)) };
            IntPtr h;
            Native.Check(Native.pose_rig_load_ex_sized(path, ref options, out h));
            Handle.Set(h);
        }

        public int JointCount { get { return (int)Native.pose_rig_joint_count(Handle); } }
        public int TissueCount { get { return (int)Native.pose_rig_tissue_count(Handle); } }
        public uint FormatVersion { get { return Native.pose_rig_format_version(Handle.DangerousGetHandle()); } }
        /// <summary>Whether Method.FEM and State.Step work on this rig (its fem section).</summary>
        public bool HasFem { get { return Native.pose_rig_has_fem(Handle) != 0; } }

        public int FindJoint(string name)
        {
            int j = Native.pose_rig_find_joint(Handle, name);
            if (j < 0)
                throw new PoseException(Status.NotFound, "the rig has no joint '" + name + "'");
            return j;
        }

        public JointInfo Joint(int joint)
        {
            JointInfo info;
            Native.Check(Native.pose_rig_joint_info(Handle, joint, out info));
            return info;
        }

        public TissueInfo Tissue(int tissue)
        {
            TissueInfo info;
            Native.Check(Native.pose_rig_tissue_info(Handle, tissue, out info));
            return info;
        }

        /// <summary>Rest positions of a tissue, copied: x0 y0 z0 x1 ...</summary>
        public float[] RestPositions(int tissue)
        {
            TissueInfo info = Tissue(tissue);
            var xyz = new float[3 * (int)info.VertexCount];
            Marshal.Copy(info.RestPositions, xyz, 0, xyz.Length);
            return xyz;
        }

        /// <summary>Rest bounds of one tissue, or (-1) of all: min, max.</summary>
        public void Bounds(int tissue, float[] min, float[] max) { Native.Check(Native.pose_rig_bounds(Handle, tissue, min, max)); }

        /// <summary>Simulation nodes (tet vertex indices) within `reach` rig units of the rest surface of the
        /// joint's bone tissues, ascending (pose_rig_fem_nodes_near_joint): for setting up, not per frame.</summary>
        public uint[] FemNodesNear(int joint, float reach)
        {
            UIntPtr n;
            Native.Check(Native.pose_rig_fem_nodes_near_joint(Handle, joint, reach, null, UIntPtr.Zero, out n));
            var nodes = new uint[(int)n];
            Native.Check(Native.pose_rig_fem_nodes_near_joint(Handle, joint, reach, nodes, n, out n));
            return nodes;
        }

        /// <summary>The rig's couplings (its `couplings` section), sorted by node.</summary>
        public FemCoupling[] FemCouplings()
        {
            var n = Native.pose_rig_fem_couplings(Handle, null, UIntPtr.Zero);
            var couplings = new FemCoupling[(int)n];
            Native.pose_rig_fem_couplings(Handle, couplings, n);
            return couplings;
        }

        /// <summary>The rig's soft-soft couplings (its `soft_couplings` section).</summary>
        public FemSoftCoupling[] FemSoftCouplings()
        {
            var size = (UIntPtr)Marshal.SizeOf(typeof(FemSoftCoupling));
            var n = Native.pose_rig_fem_soft_couplings(Handle, null, UIntPtr.Zero, size);
            var couplings = new FemSoftCoupling[(int)n];
            Native.pose_rig_fem_soft_couplings(Handle, couplings, n, size);
            return couplings;
        }

        public void Dispose() { Handle.Dispose(); }
    }

    /// <summary>One posed patient; one thread at a time. Setters return true when a limit clamped the request.</summary>
    public sealed class State : IDisposable
    {
        public readonly StateHandle Handle = new StateHandle();
        public readonly Rig Rig;

        public State(Rig rig, int threads = 0, Method method = Method.LBS)
        {
            var options = new StateOptions { Size = (UIntPtr)Marshal.SizeOf(typeof(StateOptions)), Threads = threads,
                                             Method = method };
            IntPtr h;
            Native.Check(Native.pose_state_create_ex_sized(rig.Handle, ref options, out h));
            bool added = false;
            rig.Handle.DangerousAddRef(ref added);
            Handle.Rig = rig.Handle;
            Handle.Set(h);
            Rig = rig;
        }

        public bool SetJoint(int joint, float x, float y, float z, float w)
        {
            return Native.Check(Native.pose_set_joint(Handle, joint, new[] { x, y, z, w }));
        }

        public bool SetJointEuler(int joint, float x, float y, float z, EulerOrder order = EulerOrder.XYZ)
        {
            return Native.Check(Native.pose_set_joint_euler(Handle, joint, new[] { x, y, z }, order));
        }

        /// <summary>Flexion, abduction, rotation in degrees from the neutral posture.</summary>
        public bool SetJointClinical(int joint, float flexion, float abduction, float rotation)
        {
            return Native.Check(Native.pose_set_joint_clinical(Handle, joint, new[] { flexion, abduction, rotation }));
        }

        public float[] GetJointClinical(int joint)
        {
            var deg = new float[3];
            Native.Check(Native.pose_get_joint_clinical(Handle, joint, deg));
            return deg;
        }

        public bool SetNeutral() { return Native.Check(Native.pose_set_neutral(Handle)); }
        public void Reset() { Native.Check(Native.pose_reset(Handle)); }

        public Method Method
        {
            get { return Native.pose_get_method(Handle); }
            set { Native.Check(Native.pose_set_method(Handle, value)); }
        }

        public void Apply() { Native.Check(Native.pose_apply(Handle)); }

        /// <summary>Dynamics settings (pose_set_dynamics_options); allocates the simulation.</summary>
        public void SetDynamics(DynamicsOptions options)
        {
            options.Size = (UIntPtr)Marshal.SizeOf(typeof(DynamicsOptions));
            Native.Check(Native.pose_set_dynamics_options(Handle, ref options));
        }

        /// <summary>Advance the soft tissue by dt seconds toward the posed skeleton (pose_step).</summary>
        public void Step(double dt) { Native.Check(Native.pose_step(Handle, dt)); }
        public void ResetDynamics() { Native.Check(Native.pose_reset_dynamics(Handle)); }

        public DynamicsStats DynamicsStats()
        {
            var s = new DynamicsStats { Size = (UIntPtr)Marshal.SizeOf(typeof(DynamicsStats)) };
            Native.Check(Native.pose_get_dynamics_stats(Handle, ref s));
            return s;
        }

        /// <summary>Replace the state's couplings (pose_set_fem_couplings); an empty array removes them.
        /// A refused call (InvalidArgument) leaves them as they were.</summary>
        public void SetFemCouplings(FemCoupling[] couplings)
        {
            Native.Check(Native.pose_set_fem_couplings(Handle, couplings, (UIntPtr)couplings.Length,
                                                       (UIntPtr)Marshal.SizeOf(typeof(FemCoupling))));
        }

        /// <summary>How many of the state's couplings are in effect (on nodes the simulation moves).</summary>
        public int FemCouplingCount { get { return (int)Native.pose_fem_coupling_count(Handle); } }

        /// <summary>Replace the state's soft-soft couplings (pose_set_fem_soft_couplings); an empty array
        /// removes them. A refused call (InvalidArgument) leaves them as they were.</summary>
        public void SetFemSoftCouplings(FemSoftCoupling[] couplings)
        {
            Native.Check(Native.pose_set_fem_soft_couplings(Handle, couplings, (UIntPtr)couplings.Length,
                                                            (UIntPtr)Marshal.SizeOf(typeof(FemSoftCoupling))));
        }

        /// <summary>How many of the state's soft-soft couplings are in effect (every end moved freely).</summary>
        public int FemSoftCouplingCount { get { return (int)Native.pose_fem_soft_coupling_count(Handle); } }

        /// <summary>The tet mesh's vertices after Apply or Step, copied (the nodes couplings name).</summary>
        public float[] TetPositions()
        {
            UIntPtr n;
            IntPtr p = Native.pose_tet_positions(Handle, out n);
            var xyz = new float[3 * (int)n];
            if (p != IntPtr.Zero)
                Marshal.Copy(p, xyz, 0, xyz.Length);
            return xyz;
        }

        /// <summary>Posed positions of a tissue after Apply into `xyz` (3 per vertex; reuse it every frame).</summary>
        public int CopyPositions(int tissue, float[] xyz) { return Copy(Native.pose_tissue_positions, tissue, xyz); }
        public int CopyNormals(int tissue, float[] xyz) { return Copy(Native.pose_tissue_normals, tissue, xyz); }

        public float[] Positions(int tissue)
        {
            var xyz = new float[3 * (int)Rig.Tissue(tissue).VertexCount];
            CopyPositions(tissue, xyz);
            return xyz;
        }

        delegate IntPtr Accessor(StateHandle state, int tissue, out UIntPtr count);

        int Copy(Accessor accessor, int tissue, float[] xyz)
        {
            UIntPtr n;
            IntPtr p = accessor(Handle, tissue, out n);
            if (p == IntPtr.Zero)
                throw new PoseException(Status.InvalidArgument, "no tissue " + tissue);
            if (xyz.Length < 3 * (int)n)
                throw new ArgumentException("needs room for " + (3 * (int)n) + " floats");
            Marshal.Copy(p, xyz, 0, 3 * (int)n);
            return (int)n;
        }

        public Transform JointWorld(int joint)
        {
            Transform t;
            Native.Check(Native.pose_joint_world(Handle, joint, out t));
            return t;
        }

        public void Bounds(int tissue, float[] min, float[] max) { Native.Check(Native.pose_state_bounds(Handle, tissue, min, max)); }

        public void Dispose() { Handle.Dispose(); }
    }

    /// <summary>pose_bridge_open: a clip, recording or device driving states of one rig.</summary>
    public sealed class Bridge : IDisposable
    {
        public readonly BridgeHandle Handle = new BridgeHandle();

        /// <summary>`options.Size` is set here; the other fields as pose/bridge.h documents them.</summary>
        public Bridge(string source, Rig rig, BridgeOptions options)
        {
            options.Size = (UIntPtr)Marshal.SizeOf(typeof(BridgeOptions));
            IntPtr h;
            Native.Check(Native.pose_bridge_open(source, rig.Handle, ref options, out h));
            bool added = false;
            rig.Handle.DangerousAddRef(ref added);
            Handle.Rig = rig.Handle;
            Handle.Set(h);
        }

        public BridgeFrame Apply(State state)
        {
            BridgeFrame f;
            Native.Check(Native.pose_bridge_apply(Handle, state.Handle, out f));
            return f;
        }

        public BridgeFrame PoseAt(double seconds, State state)
        {
            BridgeFrame f;
            Native.Check(Native.pose_bridge_pose_at(Handle, seconds, state.Handle, out f));
            return f;
        }

        public BridgeStatus Status()
        {
            var s = new BridgeStatus { Size = (UIntPtr)Marshal.SizeOf(typeof(BridgeStatus)) };
            Native.Check(Native.pose_bridge_status_get(Handle, ref s));
            return s;
        }

        public static string StateName(int state) { return Marshal.PtrToStringAnsi(Native.pose_bridge_state_name(state)); }

        public void Dispose() { Handle.Dispose(); }
    }
}
